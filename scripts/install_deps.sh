#!/usr/bin/env bash
# Installs every Debian package yolo_slam needs to build, test and run its demo.
# Idempotent: packages already present are skipped by apt; nothing comes from outside Debian.
set -euo pipefail

PACKAGES=(
  # build tools and the ROS 1 stack as Debian 12 ships it (see docs in ../shared/docs/ros-on-debian.md)
  build-essential cmake pkg-config git
  ros-base-dev libtf2-ros-dev libcv-bridge-dev libimage-transport-dev python3-rostest rosbash
  tf2-tools tf-tools libtf-dev rviz libdiagnostic-msgs-dev libros-rosgraph-msgs-dev
  libopencv-dev libeigen3-dev libceres-dev libopenni2-dev libgtest-dev
  python3-sensor-msgs python3-nav-msgs python3-visualization-msgs python3-geometry-msgs
  python3-std-srvs python3-rosbag python3-tf2-ros
  xvfb x11-apps imagemagick python3-numpy python3-scipy python3-matplotlib python3-yaml
  python3-opencv
  # real images and video: textures and people for the simulator, vocabulary training data,
  # reference Darknet cfgs and the darknet trainer
  opencv-doc darknet
)

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
