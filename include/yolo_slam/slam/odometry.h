#pragma once
// REP 105 for a SLAM that is its own odometry: odom -> base must be continuous, so the jumps
// of the SLAM pose (relocalisation, loop closure, global BA, a reset or a loaded map) go into
// map -> odom. Between two tracked frames with no map correction in between, odom -> base
// moves by exactly the tracked motion; across a correction (or a gap longer than max_gap_s)
// it holds still and map -> odom absorbs the jump.
#include "yolo_slam/common/geometry.h"

#include <Eigen/Core>

#include <cstddef>

namespace yolo_slam {
namespace slam {

struct OdometryEstimate {
  Pose T_map_odom = Pose::Identity();
  Pose T_odom_base = Pose::Identity();
  // Velocity of base in its own frame (ROS nav_msgs/Odometry twist convention), zero when the
  // pose held still across a correction.
  Eigen::Vector3d linear = Eigen::Vector3d::Zero(), angular = Eigen::Vector3d::Zero();
  bool jumped = false;  // this update absorbed a map correction into map -> odom
};

class ContinuousOdometry {
 public:
  // A gap without a tracked frame longer than this is not bridged by the motion (the base may
  // have moved unseen): odom holds still and map -> odom takes the difference.
  static constexpr double kDefaultMaxGapS = 1.0;
  explicit ContinuousOdometry(double max_gap_s = kDefaultMaxGapS) : max_gap_s_(max_gap_s) {}

  // A tracked frame: base pose in the map frame, and System::mapCorrections() after tracking it.
  OdometryEstimate update(double stamp, const Pose& T_map_base, size_t corrections);
  void reset() { has_last_ = false; }

 private:
  double max_gap_s_;
  bool has_last_ = false;
  double last_stamp_ = 0;
  size_t last_corrections_ = 0;
  Pose last_map_base_ = Pose::Identity();
  Pose odom_base_ = Pose::Identity();
};

}  // namespace slam
}  // namespace yolo_slam
