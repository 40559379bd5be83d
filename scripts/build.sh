#!/usr/bin/env bash
# Builds yolo_slam in a catkin workspace under build/ws (Release, -j2, incremental).
# Binaries land in build/ws/devel/lib/yolo_slam/; `source build/ws/devel/setup.bash` then
# `rosrun yolo_slam <tool>` or `roslaunch yolo_slam <file>.launch`.
# Extra arguments are passed to catkin_make (for example a target name such as `tests`).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"

mkdir -p "$YS_WS/src"
if [ ! -e "$YS_WS/src/yolo_slam" ]; then
  ln -s ../../.. "$YS_WS/src/yolo_slam"
fi
[ -e "$YS_WS/src/CMakeLists.txt" ] || ln -s /usr/share/catkin/cmake/toplevel.cmake "$YS_WS/src/CMakeLists.txt"

cd "$YS_WS"
catkin_make -j2 -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 "$@"
