#!/usr/bin/env bash
# Installs every Debian package yolo_slam needs to build, test and run its demo: the one list
# of the project's Debian packages. Each "key:" row below is a dependency key of package.xml
# with the Debian packages that provide it (test/common/test_package_manifest.cpp checks that the two
# match); the rows without a key are build tools and data the package.xml has no key for.
# Idempotent: packages already present are skipped; nothing comes from outside Debian.
set -euo pipefail

DEPENDENCIES='
  build tools:        build-essential cmake pkg-config git
  catkin:             catkin ros-base-dev
  roscpp:             libroscpp-dev
  nodelet:            libnodelet-dev
  pluginlib:          pluginlib-dev
  std_msgs:           libstd-msgs-dev
  std_srvs:           libstd-srvs-dev python3-std-srvs
  sensor_msgs:        libsensor-msgs-dev python3-sensor-msgs
  geometry_msgs:      libgeometry-msgs-dev python3-geometry-msgs
  nav_msgs:           libnav-msgs-dev python3-nav-msgs
  visualization_msgs: libvisualization-msgs-dev python3-visualization-msgs
  diagnostic_msgs:    libdiagnostic-msgs-dev python3-diagnostic-msgs
  diagnostic_updater: libdiagnostic-updater-dev
  tf2_ros:            libtf2-ros-dev python3-tf2-ros
  tf2_eigen:          libtf2-eigen-dev
  cv_bridge:          libcv-bridge-dev
  message_filters:    libmessage-filters-dev
  image_transport:    libimage-transport-dev
  dynamic_reconfigure: libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  camera_info_manager: libcamera-info-manager-dev
  image_geometry:     libimage-geometry-dev
  libopencv-dev:      libopencv-dev
  eigen:              libeigen3-dev
  libceres-dev:       libceres-dev
  libopenni2-dev:     libopenni2-dev
  nlohmann-json-dev:  nlohmann-json3-dev
  libcereal-dev:      libcereal-dev
  liboctomap-dev:     liboctomap-dev octomap-tools
  message_generation: ros-message-generation
  message_runtime:    ros-message-runtime
  roslaunch:          python3-roslaunch rosbash
  rosbag:             python3-rosbag
  rviz:               rviz
  rospy:              python3-rospy
  tf2_msgs:           python3-tf2-msgs
  python3-opencv:     python3-opencv
  python3-numpy:      python3-numpy
  rostest:            python3-rostest
  rosgraph_msgs:      libros-rosgraph-msgs-dev
  gtest:              libgtest-dev
  xvfb:               xvfb
  imagemagick:        imagemagick
  data:               opencv-doc darknet
  optional:           libdeflate-dev
'
# data: real images and video (textures and people for the simulator, vocabulary training
# data), reference Darknet cfgs and the darknet trainer.
# optional: libraries the build uses when present and works without (no rosdep key needed):
# libdeflate decodes the dataset PNGs about twice as fast as OpenCV (src/io/image_file.cpp).

if [ "${1:-}" = "--list" ]; then
  echo "$DEPENDENCIES"
  exit 0
fi

PACKAGES=()
while IFS= read -r row; do
  [ -n "${row// /}" ] || continue
  for p in ${row#*:}; do PACKAGES+=("$p"); done
done <<< "$DEPENDENCIES"

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
echo "install_deps: installing ${#missing[@]} packages: ${missing[*]}"
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install_deps: done"
