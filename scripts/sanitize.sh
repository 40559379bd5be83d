#!/usr/bin/env bash
# Sanitizer run of the core gtests (no ROS): configures build/sanitize-<kind>, builds the tests
# and runs them with ctest. Exits non-zero if anything fails to build, any test fails, or any
# sanitizer report appears in the test output (also one a test might have swallowed, e.g. from a
# tool it ran as a child process).
#   scripts/sanitize.sh [address|thread]     (default: address = ASan + UBSan; thread = TSan)
# Environment: JOBS (make -j, default 2), CTEST_ARGS (extra ctest arguments, e.g. "-R vocabulary"),
# SANITIZE_BUILD_DIR (reuse another build folder configured for the same sanitizer),
# YS_FUZZ_ITERATIONS (address only: after the suite, the fuzz tests (ctest -R fuzz) run again with
# this many mutants per target, default 10000; 0 skips that run).
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"

kind="${1:-address}"
case "$kind" in
  address|thread) ;;
  -h|--help) sed -n '2,8p' "${BASH_SOURCE[0]}"; exit 0 ;;
  *) echo "error: unknown sanitizer '$kind': use 'address' (ASan+UBSan) or 'thread' (TSan)"; exit 1 ;;
esac

build="${SANITIZE_BUILD_DIR:-$YS_ROOT/build/sanitize-$kind}"
supp_dir="$YS_ROOT/test/sanitizers"
log="$build/sanitize.log"
mkdir -p "$build" || exit 1

# The same options the CMake sanitizer build gives ctest; set here too so the script does not
# depend on them. Suppressions cover uninstrumented system libraries only (see tsan.supp).
export TSAN_OPTIONS="suppressions=$supp_dir/tsan.supp:second_deadlock_stack=1${TSAN_OPTIONS:+:$TSAN_OPTIONS}"
export ASAN_OPTIONS="detect_leaks=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"

nice -n 10 cmake -S "$YS_ROOT" -B "$build" -DYOLO_SLAM_WITH_ROS=OFF -DYOLO_SLAM_SANITIZE="$kind" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo > "$build/cmake.log" 2>&1 \
  || { tail -20 "$build/cmake.log"; echo "sanitize.sh: FAILED: cmake (see $build.cmake.log)"; exit 1; }
nice -n 10 make -C "$build" -j"${JOBS:-2}" tests > "$build/make.log" 2>&1 \
  || { grep -E "error|Error" "$build/make.log" | head -20; echo "sanitize.sh: FAILED: build (see $build/make.log)"; exit 1; }

if [ "$kind" = thread ]; then
  # The suppressions must not hide a race between two of our own threads: both deliberate races
  # (a global, and cv::Mat pixels allocated inside OpenCV) have to be reported with them in force.
  canary="$build/race_canary"
  nice -n 10 g++ -std=c++17 -O1 -g -fsanitize=thread -fno-omit-frame-pointer \
    "$supp_dir/race_canary.cpp" $(pkg-config --cflags opencv4) -lopencv_core -o "$canary" \
    || { echo "sanitize.sh: FAILED: cannot build $supp_dir/race_canary.cpp"; exit 1; }
  "$canary" > "$build/race_canary.log" 2>&1
  canary_status=$?
  if [ $canary_status -ne 66 ] || ! grep -q "g_counter" "$build/race_canary.log" \
     || ! grep -q "cv::fastMalloc" "$build/race_canary.log"; then
    echo "sanitize.sh: FAILED: TSan did not report both deliberate races in race_canary.cpp (exit $canary_status):"
    echo "  an entry in $supp_dir/tsan.supp is too broad (see $build/race_canary.log)"
    exit 1
  fi
  echo "sanitize.sh: race canary reported as expected (suppressions do not hide our races)"
fi

cd "$build" || exit 1
fuzz_iterations="${YS_FUZZ_ITERATIONS:-10000}"
unset YS_FUZZ_ITERATIONS  # the suite runs the fuzz tests at their default size

# Fails (exit 1) if a sanitizer report is in ctest's last log; $1 names the run.
check_reports() {
  local pattern='WARNING: ThreadSanitizer|ERROR: AddressSanitizer|ERROR: LeakSanitizer|runtime error:'
  local reports
  reports=$(grep -cE "$pattern" "$build/Testing/Temporary/LastTest.log" 2>/dev/null)
  reports=${reports:-0}
  if [ "$reports" -gt 0 ]; then
    grep -E "$pattern|SUMMARY: " "$build/Testing/Temporary/LastTest.log" | sort | uniq -c | sort -rn | head -20
    echo "sanitize.sh: FAILED: $reports sanitizer report(s) in $1 (full text in $build/Testing/Temporary/LastTest.log)"
    exit 1
  fi
}

# One test at a time: the SLAM tests start threads of their own and the sanitizers are slow.
# shellcheck disable=SC2086
nice -n 10 ctest --output-on-failure --timeout 1800 ${CTEST_ARGS:-} 2>&1 | tee "$log"
status=${PIPESTATUS[0]}
check_reports "the test suite"
if [ $status -ne 0 ]; then
  echo "sanitize.sh: FAILED: ctest exit $status (see $log)"
  exit 1
fi
if ! grep -qE "tests passed, 0 tests failed out of [1-9]" "$log"; then
  echo "sanitize.sh: FAILED: no tests ran (see $log)"
  exit 1
fi
summary=$(grep -E 'tests passed' "$log")

# The readers of user files, fuzzed longer under ASan/UBSan (bounded: a fixed number of mutants).
if [ "$kind" = address ] && [ "$fuzz_iterations" -gt 0 ]; then
  fuzz_log="$build/fuzz.log"
  YS_FUZZ_ITERATIONS="$fuzz_iterations" nice -n 10 ctest --output-on-failure --timeout 3600 -R fuzz 2>&1 | tee "$fuzz_log"
  fuzz_status=${PIPESTATUS[0]}
  check_reports "the fuzz run"
  if [ $fuzz_status -ne 0 ] || ! grep -qE "tests passed, 0 tests failed out of [1-9]" "$fuzz_log"; then
    echo "sanitize.sh: FAILED: fuzz run with $fuzz_iterations mutants per target (see $fuzz_log)"
    exit 1
  fi
  summary="$summary; fuzz tests with $fuzz_iterations mutants per target clean"
fi
echo "sanitize.sh: $kind sanitizer clean ($summary)"
