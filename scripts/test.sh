#!/usr/bin/env bash
# The test command: installs missing dependencies, builds, builds the tests, runs every gtest
# and rostest through catkin, and exits non-zero if any test failed (catkin's run_tests alone
# exits 0 on failure, so the verdict comes from catkin_test_results).
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"

bash "$YS_ROOT/scripts/install_deps.sh" || exit 1
bash "$YS_ROOT/scripts/build.sh" || { echo "test.sh: build failed"; exit 1; }
bash "$YS_ROOT/scripts/build.sh" tests || { echo "test.sh: building tests failed"; exit 1; }

cd "$YS_WS"
rm -rf build/test_results
set +u; source devel/setup.bash; set -u
# One test at a time: the rostests each start a master, and the machine has two cores.
catkin_make --source .src -j1 run_tests -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 > build/run_tests.log 2>&1
run_status=$?
grep -E "^\[ *(RUN|  OK|  FAILED|  PASSED) |FAILURE|Failure|error:" build/run_tests.log | grep -v "^\[ RUN" | tail -200 || true

echo "----------------------------------------------------------------"
catkin_test_results build/test_results --verbose > build/test_summary.txt 2>&1
status=$?
grep -v "^Skipping" build/test_summary.txt | tail -40
# run_tests exits 0 when tests fail but not when something could not be built or run; and a
# run that produced no result files must not read as a pass.
if [ $run_status -ne 0 ]; then
  grep -E "error|Error" build/run_tests.log | head -20
  echo "test.sh: FAILED: run_tests could not build or run the tests (see $YS_WS/build/run_tests.log)"
  exit 1
fi
if ! grep -qE "^Summary: [1-9][0-9]* tests" build/test_summary.txt; then
  echo "test.sh: FAILED: no test results were produced (see $YS_WS/build/run_tests.log)"
  exit 1
fi
if [ $status -ne 0 ]; then
  echo "test.sh: FAILED (see $YS_WS/build/run_tests.log)"
  exit 1
fi
echo "test.sh: all tests passed ($(tail -1 build/test_summary.txt))"
