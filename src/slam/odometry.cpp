#include "yolo_slam/slam/odometry.h"

#include <Eigen/Geometry>

namespace yolo_slam {
namespace slam {

OdometryEstimate ContinuousOdometry::update(double stamp, const Pose& T_map_base, size_t corrections) {
  OdometryEstimate e;
  const double dt = stamp - last_stamp_;
  const bool bridged = has_last_ && corrections == last_corrections_ && dt > 0 && dt <= max_gap_s_;
  if (bridged) {
    const Pose step = last_map_base_.inverse() * T_map_base;
    odom_base_ = odom_base_ * step;
    e.linear = step.translation() / dt;
    const Eigen::AngleAxisd aa(step.rotation());
    e.angular = aa.axis() * (aa.angle() / dt);
  } else {
    e.jumped = has_last_;
  }
  // The first frame starts odom at the map origin's pose of base: map -> odom identity.
  if (!has_last_) odom_base_ = T_map_base;
  has_last_ = true;
  last_stamp_ = stamp;
  last_corrections_ = corrections;
  last_map_base_ = T_map_base;
  e.T_odom_base = odom_base_;
  e.T_map_odom = T_map_base * odom_base_.inverse();
  return e;
}

}  // namespace slam
}  // namespace yolo_slam
