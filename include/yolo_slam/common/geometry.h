#pragma once
// Pose conventions used everywhere: T_ab maps coordinates in frame b into frame a
// (p_a = T_ab * p_b). Trajectories store T_wc (camera-to-world), as TUM files do.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace yolo_slam {

using Pose = Eigen::Isometry3d;

struct StampedPose {
  double stamp = 0.0;
  Pose T_wc = Pose::Identity();
};
using Trajectory = std::vector<StampedPose>;

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Rotation angle of a rotation matrix in radians, robust near 0 and pi.
inline double rotationAngle(const Eigen::Matrix3d& R) {
  double c = std::min(1.0, std::max(-1.0, (R.trace() - 1.0) * 0.5));
  return std::acos(c);
}

// How far apart two camera poses (T_cw) are: the distance between the camera centres (metres)
// and the angle of the rotation between them (radians).
struct PoseGap {
  double moved_m = 0.0;
  double turned_rad = 0.0;
};
inline PoseGap poseGap(const Pose& a_cw, const Pose& b_cw) {
  return {(a_cw.inverse().translation() - b_cw.inverse().translation()).norm(),
          Eigen::AngleAxisd((a_cw * b_cw.inverse()).linear()).angle()};
}

inline Pose makePose(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) {
  Pose T = Pose::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

}  // namespace yolo_slam
