# Sourced by the other scripts: a clean PATH (pyenv's python3 lacks catkin_pkg) and the
# workspace locations. Source build/ws/devel/setup.bash yourself to use rosrun/roslaunch.
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:/usr/local/bin
YS_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
YS_WS="$YS_ROOT/build/ws"
export YOLO_SLAM_SHARED="${YOLO_SLAM_SHARED:-$(cd "$YS_ROOT/.." && pwd)/shared}"
export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
