#pragma once
// SE3 parameter blocks for Ceres.
//
// A pose block is 7 doubles [qx qy qz qw tx ty tz] (Eigen quaternion order, then translation)
// holding T_cw. Its tangent is 6-dimensional, delta = [phi (rotation), rho (translation)], with
// the left update used by g2o/ORB-SLAM2:  R' = Exp(phi) R,  t' = Exp(phi) t + rho,
// so a camera point p_c = R X + t moves as p_c' = Exp(phi) p_c + rho (d p_c / d delta =
// [-[p_c]x, I]).
//
// SE3LeftManifold reports PlusJacobian = [I6; 0]: cost functions used with it write their
// Jacobian with respect to the 6 tangent coordinates into the first 6 columns of the 7-column
// "ambient" Jacobian and zero in the last. This is only valid together with this manifold.
#include "yolo_slam/common/geometry.h"

#include <ceres/manifold.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace yolo_slam {
namespace optimization {

constexpr int kPoseParams = 7;
constexpr int kPoseTangent = 6;

// Exponential map of so(3) (Rodrigues), stable for tiny angles.
Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi);
// Logarithm of SO(3): rotation vector with angle in [0, pi].
Eigen::Vector3d logSO3(const Eigen::Matrix3d& R);

void poseToParams(const Pose& T, double* params);
Pose paramsToPose(const double* params);

class SE3LeftManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseParams; }
  int TangentSize() const override { return kPoseTangent; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace optimization
}  // namespace yolo_slam
