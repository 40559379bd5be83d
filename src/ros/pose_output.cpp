#include "pose_output.h"

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "yolo_slam/common/error.h"
#include "yolo_slam/ros/conversions.h"

namespace yolo_slam {
namespace ros1 {

namespace {

// Below this many inliers the pose covariance grows as reference / inliers.
constexpr double kReferenceInliers = 100.0;
// Variances (m^2, rad^2) at kReferenceInliers or more: about 1 cm and 0.6 degrees, the size of
// the pose error of tracking on the walking presets (BENCHMARKS.md, RPE per frame).
constexpr double kDefaultPoseVariance = 1e-4;
constexpr double kDefaultTwistVariance = 1e-2;

// [x y z qx qy qz qw] -> Pose; throws Error naming the parameter.
Pose poseFromParam(const std::vector<double>& v, const std::string& name) {
  if (v.size() != 7)
    throw Error("parameter " + name + " needs 7 numbers [x, y, z, qx, qy, qz, qw], got " + std::to_string(v.size()));
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (!(q.norm() > 1e-9)) throw Error("parameter " + name + " has a zero (or NaN) quaternion");
  return makePose(q.normalized(), Eigen::Vector3d(v[0], v[1], v[2]));
}

std::array<double, 6> varianceParam(::ros::NodeHandle& pnh, const std::string& key, double def) {
  std::vector<double> v(6, def);
  pnh.param(key, v, v);
  if (v.size() != 6)
    throw Error("parameter " + pnh.resolveName(key) + " needs 6 variances [x, y, z, roll, pitch, yaw], got " +
                std::to_string(v.size()));
  std::array<double, 6> out{};
  for (size_t i = 0; i < 6; ++i) {
    if (!(v[i] > 0) || !std::isfinite(v[i]))
      throw Error("parameter " + pnh.resolveName(key) + ": variances must be finite and > 0");
    out[i] = v[i];
  }
  return out;
}

geometry_msgs::TransformStamped stampedTransform(const ::ros::Time& stamp, const std::string& parent,
                                                 const std::string& child, const Pose& T) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform = transformToMsg(T);
  return t;
}

}  // namespace

PoseOutput::PoseOutput(::ros::NodeHandle& nh, ::ros::NodeHandle& pnh) : tf_listener_(tf_buffer_) {
  pnh.param<std::string>("map_frame", map_frame_, "map");
  pnh.param<std::string>("odom_frame", odom_frame_, "odom");
  pnh.param<std::string>("base_frame", base_frame_, "base_link");
  pnh.param<std::string>("camera_frame", camera_frame_param_, "");
  pnh.param("publish_tf", publish_tf_, true);
  pnh.param("publish_odom_tf", publish_odom_tf_, true);
  pnh.param("publish_map_to_camera", map_to_camera_, false);
  pnh.param("tf_timeout", tf_timeout_s_, 2.0);
  std::vector<double> b2c;
  pnh.param("base_to_camera", b2c, b2c);
  mount_from_param_ = !b2c.empty();
  if (mount_from_param_) T_bc_ = poseFromParam(b2c, pnh.resolveName("base_to_camera"));
  pose_variance_ = varianceParam(pnh, "pose_covariance", kDefaultPoseVariance);
  twist_variance_ = varianceParam(pnh, "twist_covariance", kDefaultTwistVariance);
  pose_pub_ = nh.advertise<geometry_msgs::PoseStamped>("yolo_slam/pose", 10);
  pose_cov_pub_ = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("yolo_slam/pose_with_covariance", 10);
  odom_pub_ = nh.advertise<nav_msgs::Odometry>("yolo_slam/odom", 10);
}

std::string PoseOutput::describe() const {
  if (!publish_tf_) return "tf off";
  if (map_to_camera_) return map_frame_ + " -> camera";
  const std::string mount = mount_from_param_ ? " (" + base_frame_ + " -> camera from ~base_to_camera, on /tf_static)"
                                              : " (" + base_frame_ + " -> camera read from tf)";
  if (publish_odom_tf_) return map_frame_ + " -> " + odom_frame_ + " -> " + base_frame_ + mount;
  return map_frame_ + " -> " + odom_frame_ + " (odometry from tf)" + mount;
}

bool PoseOutput::ready(const std::string& msg_frame_id) {
  if (camera_frame_.empty()) {
    camera_frame_ = camera_frame_param_.empty() ? msg_frame_id : camera_frame_param_;
    // TUM bags name frames "/openni_rgb_optical_frame"; tf2 frame ids may not start with '/'.
    while (!camera_frame_.empty() && camera_frame_.front() == '/') camera_frame_.erase(0, 1);
    if (camera_frame_.empty()) camera_frame_ = "camera_rgb_optical_frame";
  }
  if (!mount_known_) mount_known_ = resolveMount();
  return mount_known_;
}

bool PoseOutput::resolveMount() {
  if (map_to_camera_ || mount_from_param_) {
    if (mount_from_param_ && publish_tf_ && !map_to_camera_ && !mount_published_) {
      static_broadcaster_.sendTransform(stampedTransform(::ros::Time::now(), base_frame_, camera_frame_, T_bc_));
      mount_published_ = true;
    }
    return true;
  }
  // The first frame waits for tf to fill (the static publisher may start after us); later
  // frames only look.
  const ::ros::Duration wait(waited_for_tf_ ? 0.0 : tf_timeout_s_);
  waited_for_tf_ = true;
  try {
    const auto t = tf_buffer_.lookupTransform(base_frame_, camera_frame_, ::ros::Time(0), wait);
    T_bc_ = transformFromMsg(t.transform);
    ROS_INFO("Slam: %s -> %s read from tf", base_frame_.c_str(), camera_frame_.c_str());
    return true;
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5.0,
                       "Slam: no %s -> %s transform in tf (%s): frames are not tracked until it exists. Publish it "
                       "(robot_state_publisher with a URDF, or a static_transform_publisher), or give it as "
                       "~base_to_camera [x, y, z, qx, qy, qz, qw]",
                       base_frame_.c_str(), camera_frame_.c_str(), e.what());
    return false;
  }
}

Pose PoseOutput::publishedPose(const Pose& T_wc) const {
  // The map frame is the first base pose: camera world -> map is the mount, so the map is
  // z-up whenever base_link is.
  return map_to_camera_ ? T_bc_ * T_wc : T_bc_ * T_wc * T_bc_.inverse();
}

std::array<double, 36> PoseOutput::covariance(const std::array<double, 6>& diag, double scale) const {
  std::array<double, 36> c{};
  for (size_t i = 0; i < 6; ++i) c[i * 6 + i] = diag[i] * scale;
  return c;
}

geometry_msgs::PoseStamped PoseOutput::publish(const ::ros::Time& stamp, const Pose& T_wc, int inliers,
                                               size_t corrections) {
  const Pose T_map_pub = publishedPose(T_wc);
  const double scale = std::max(1.0, kReferenceInliers / std::max(1, inliers));
  geometry_msgs::PoseStamped ps;
  ps.header.stamp = stamp;
  ps.header.frame_id = map_frame_;
  ps.pose = poseToMsg(T_map_pub);
  pose_pub_.publish(ps);
  geometry_msgs::PoseWithCovarianceStamped pc;
  pc.header = ps.header;
  pc.pose.pose = ps.pose;
  const auto cov = covariance(pose_variance_, scale);
  std::copy(cov.begin(), cov.end(), pc.pose.covariance.begin());
  pose_cov_pub_.publish(pc);
  if (map_to_camera_) {
    if (publish_tf_) tf_broadcaster_.sendTransform(stampedTransform(stamp, map_frame_, camera_frame_, T_map_pub));
    return ps;
  }
  const slam::OdometryEstimate odo = odometry_.update(stamp.toSec(), T_map_pub, corrections);
  if (odo.jumped)
    ROS_INFO("Slam: the map moved under the camera (relocalisation, loop closure or map change) at %.3f; "
             "%s -> %s absorbs the jump",
             stamp.toSec(), map_frame_.c_str(), odom_frame_.c_str());
  if (publish_odom_tf_) {
    publishOdometry(stamp, odo, scale);
    if (publish_tf_) publishOwnTf(stamp, T_map_pub, odo);
  } else if (publish_tf_) {
    publishExternalOdomCorrection(stamp, T_map_pub);
  }
  return ps;
}

void PoseOutput::publishOwnTf(const ::ros::Time& stamp, const Pose& T_map_base, const slam::OdometryEstimate& odo) {
  std::vector<geometry_msgs::TransformStamped> tfs{stampedTransform(stamp, map_frame_, odom_frame_, odo.T_map_odom),
                                                   stampedTransform(stamp, odom_frame_, base_frame_, odo.T_odom_base)};
  tf_broadcaster_.sendTransform(tfs);
}

void PoseOutput::publishExternalOdomCorrection(const ::ros::Time& stamp, const Pose& T_map_base) {
  // Wheel/IMU odometry publishes odom -> base_link; we correct its drift with map -> odom.
  try {
    const auto t = tf_buffer_.lookupTransform(odom_frame_, base_frame_, stamp, ::ros::Duration(0.1));
    const Pose T_odom_base = transformFromMsg(t.transform);
    tf_broadcaster_.sendTransform(stampedTransform(stamp, map_frame_, odom_frame_, T_map_base * T_odom_base.inverse()));
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(2.0,
                       "Slam: no %s -> %s transform at %.3f (%s); map -> odom not published. Set ~publish_odom_tf "
                       "true if nothing else publishes odometry",
                       odom_frame_.c_str(), base_frame_.c_str(), stamp.toSec(), e.what());
  }
}

void PoseOutput::publishOdometry(const ::ros::Time& stamp, const slam::OdometryEstimate& odo, double scale) {
  nav_msgs::Odometry m;
  m.header.stamp = stamp;
  m.header.frame_id = odom_frame_;
  m.child_frame_id = base_frame_;
  m.pose.pose = poseToMsg(odo.T_odom_base);
  const auto pc = covariance(pose_variance_, scale);
  std::copy(pc.begin(), pc.end(), m.pose.covariance.begin());
  m.twist.twist.linear.x = odo.linear.x();
  m.twist.twist.linear.y = odo.linear.y();
  m.twist.twist.linear.z = odo.linear.z();
  m.twist.twist.angular.x = odo.angular.x();
  m.twist.twist.angular.y = odo.angular.y();
  m.twist.twist.angular.z = odo.angular.z();
  const auto tc = covariance(twist_variance_, scale);
  std::copy(tc.begin(), tc.end(), m.twist.covariance.begin());
  odom_pub_.publish(m);
}

}  // namespace ros1
}  // namespace yolo_slam
