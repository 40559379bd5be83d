#pragma once
// What the Slam nodelet tells the robot about where it is: the pose, the pose with covariance,
// nav_msgs/Odometry and tf, following REP 103/105.
//   map -> odom      published by us: absorbs every jump of the SLAM pose (relocalisation, loop
//                    closure, global BA, a reset or a loaded map), so that
//   odom -> base     stays continuous (slam::ContinuousOdometry); or, with ~publish_odom_tf
//                    false, taken from tf (wheel/IMU odometry) and only map -> odom is ours;
//   base -> camera   not ours when it is in tf (URDF, static_transform_publisher): read once.
//                    Given as ~base_to_camera instead, it is published once on /tf_static.
// With ~publish_map_to_camera: map -> camera only (no base, no odom), for a bare camera.
#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <array>
#include <memory>
#include <string>

#include "yolo_slam/common/geometry.h"
#include "yolo_slam/slam/odometry.h"

namespace yolo_slam {
namespace ros1 {

class PoseOutput {
 public:
  // Reads the frame and tf parameters from `pnh` (README: Slam nodelet parameters); throws
  // yolo_slam::Error naming a bad parameter.
  PoseOutput(::ros::NodeHandle& nh, ::ros::NodeHandle& pnh);

  // The camera frame of a frame message (~camera_frame overrides it; a leading '/' of TUM bags
  // is dropped). Resolves base -> camera on the first call (tf, waiting up to ~tf_timeout) and
  // returns false while it is unknown; the caller then leaves the frame out (error logged).
  bool ready(const std::string& msg_frame_id);

  // A tracked frame: camera pose T_wc in the SLAM world, its inliers (covariance scale) and
  // System::mapCorrections() after it. Returns the published pose (for the path).
  geometry_msgs::PoseStamped publish(const ::ros::Time& stamp, const Pose& T_wc, int inliers, size_t corrections);

  // The SLAM world (the first camera frame) expressed in the map frame: points and keyframes.
  Pose worldInMap() const { return T_bc_; }
  // The published pose (base, or the camera with ~publish_map_to_camera) of T_wc in map.
  Pose publishedPose(const Pose& T_wc) const;
  const std::string& mapFrame() const { return map_frame_; }
  std::string describe() const;

 private:
  bool resolveMount();
  void publishOwnTf(const ::ros::Time& stamp, const Pose& T_map_base, const slam::OdometryEstimate& odo);
  void publishExternalOdomCorrection(const ::ros::Time& stamp, const Pose& T_map_base);
  void publishOdometry(const ::ros::Time& stamp, const slam::OdometryEstimate& odo, double scale);
  std::array<double, 36> covariance(const std::array<double, 6>& diag, double scale) const;

  // Parameters (const after the constructor).
  std::string map_frame_, odom_frame_, base_frame_, camera_frame_param_;
  bool publish_tf_ = true, publish_odom_tf_ = true, map_to_camera_ = false, mount_from_param_ = false;
  double tf_timeout_s_ = 2.0;
  std::array<double, 6> pose_variance_{}, twist_variance_{};

  // Frame callback state (its callbacks are serialised; nothing else touches these).
  std::string camera_frame_;
  bool mount_known_ = false, mount_published_ = false, waited_for_tf_ = false;
  Pose T_bc_ = Pose::Identity();  // camera pose in base
  slam::ContinuousOdometry odometry_;

  ::ros::Publisher pose_pub_, pose_cov_pub_, odom_pub_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
};

}  // namespace ros1
}  // namespace yolo_slam
