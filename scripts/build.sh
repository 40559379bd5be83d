#!/usr/bin/env bash
# Builds yolo_slam in a catkin workspace under build/ws (Release, -j2, incremental).
# Binaries land in build/ws/devel/lib/yolo_slam/; `source build/ws/devel/setup.bash` then
# `rosrun yolo_slam <tool>` or `roslaunch yolo_slam <file>.launch`.
# Extra arguments are passed to catkin_make (for example a target name such as `tests`).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"

# The workspace's source space is the hidden folder build/ws/.src holding a link to the
# repository. Hidden, because roslaunch/rostest look files up by walking the package folder
# with symlinks followed and skip only dot-folders: a visible build/ws/src/yolo_slam -> repo
# link would make that walk loop forever.
mkdir -p "$YS_WS/.src"
[ -e "$YS_WS/.src/yolo_slam" ] || ln -s ../../.. "$YS_WS/.src/yolo_slam"
[ -e "$YS_WS/.src/CMakeLists.txt" ] || ln -s /usr/share/catkin/cmake/toplevel.cmake "$YS_WS/.src/CMakeLists.txt"
# A workspace configured with the older visible src/ layout is rebuilt from scratch.
if [ -e "$YS_WS/src" ]; then rm -rf "$YS_WS/src" "$YS_WS/build" "$YS_WS/devel"; fi

# `scripts/build.sh install` fills build/ws/.install: hidden for the same reason, as a visible
# install space inside the repository would hold a second copy of every launch file for
# roslaunch to find ("multiple files named tum_bag.launch").
cd "$YS_WS"
catkin_make --source .src -j2 -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" \
  -DCMAKE_INSTALL_PREFIX="$YS_WS/.install" \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 "$@"
