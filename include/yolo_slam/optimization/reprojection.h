#pragma once
// Reprojection residuals with analytic Jacobians (pose blocks use SE3LeftManifold, se3.h).
//
// Monocular: r = sqrt(inv_sigma2) * (pi(p_c) - uv), 2 rows.
// RGB-D ("stereo" in ORB-SLAM2): a third row for the virtual right coordinate
//   u_r = fx x/z + cx - bf/z, compared with the keypoint's u - bf/depth.
// chi2 = |r|^2 is compared with 5.991 (2 dof) / 7.815 (3 dof) at 95%.
#include "yolo_slam/common/camera.h"

#include <ceres/sized_cost_function.h>
#include <cmath>
#include <Eigen/Core>

namespace yolo_slam {
namespace optimization {

constexpr double kChi2Mono = 5.991;
constexpr double kChi2Stereo = 7.815;

// The chi2 bound of an observation: 3 rows with a right coordinate (u_right >= 0), else 2.
inline double chi2Threshold(double u_right) { return u_right >= 0 ? kChi2Stereo : kChi2Mono; }

struct Intrinsics {
  double fx, fy, cx, cy, bf;
  static Intrinsics from(const CameraModel& c) { return {c.fx, c.fy, c.cx, c.cy, c.bf}; }
};

// Shared residual/Jacobian code. kRows = 2 (mono) or 3 (stereo). Returns false when the point
// lies on the camera plane (|z| tiny); the solver then rejects that step.
template <int kRows>
bool reprojectionResidual(const Intrinsics& K, const double* pose, const Eigen::Vector3d& Xw,
                          const double* obs, double sqrt_info, double* residuals,
                          double* jac_pose /* kRows x 7 row-major or null */,
                          double* jac_point /* kRows x 3 row-major or null */);

// Camera point and squared error (chi2, information-weighted) without Jacobians.
struct ReprojectionCheck {
  double chi2;
  double depth;  // z of the point in the camera
};
ReprojectionCheck checkReprojection(const Intrinsics& K, const double* pose,
                                    const Eigen::Vector3d& Xw, const Eigen::Vector2d& uv,
                                    double u_right, double inv_sigma2);

// Huber kernel on one observation's whitened residual r (rows x 1) and its pose Jacobian J
// (rows x 7 row-major, may be null), threshold delta^2 = chi2: beyond it the cost is
// rho(s) = 2 delta sqrt(s) - delta^2 of s = |r|^2. r becomes g r with g^2 = rho(s) / s, so
// |r|^2 = rho(s), and J its exact Jacobian g (I - c r r^T) J, c = (delta sqrt(s) - delta^2) /
// (s rho(s)); the gradient is then rho'(s) J^T r, as with a ceres::HuberLoss on the block.
inline void applyHuber(int rows, double chi2, double* r, double* J) {
  constexpr int kCols = 7;
  double s = 0;
  for (int k = 0; k < rows; ++k) s += r[k] * r[k];
  if (!(s > chi2)) return;
  const double delta = std::sqrt(chi2), root = std::sqrt(s);
  const double rho = 2 * delta * root - chi2;
  const double g = std::sqrt(rho / s);
  if (J) {
    const double c = (delta * root - chi2) / (s * rho);
    double rJ[kCols] = {0};
    for (int i = 0; i < rows; ++i)
      for (int k = 0; k < kCols; ++k) rJ[k] += r[i] * J[i * kCols + k];
    for (int i = 0; i < rows; ++i)
      for (int k = 0; k < kCols; ++k) J[i * kCols + k] = g * (J[i * kCols + k] - c * r[i] * rJ[k]);
  }
  for (int k = 0; k < rows; ++k) r[k] *= g;
}

// Pose-only: the 3D point is a constant. `active` (may be null) lets the pose optimizer switch
// an observation off without rebuilding the problem: an inactive residual is 0 with zero
// Jacobian (ORB-SLAM2's "level 1" edges).
template <int kRows>
class PoseOnlyCost final : public ceres::SizedCostFunction<kRows, 7> {
 public:
  PoseOnlyCost(const Intrinsics& K, const Eigen::Vector3d& Xw, const Eigen::Matrix<double, kRows, 1>& obs,
               double inv_sigma2, const bool* active)
      : K_(K), Xw_(Xw), obs_(obs), sqrt_info_(std::sqrt(inv_sigma2)), active_(active) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (active_ && !*active_) {
      for (int i = 0; i < kRows; ++i) residuals[i] = 0.0;
      if (jacobians && jacobians[0]) {
        for (int i = 0; i < kRows * 7; ++i) jacobians[0][i] = 0.0;
      }
      return true;
    }
    return reprojectionResidual<kRows>(K_, parameters[0], Xw_, obs_.data(), sqrt_info_, residuals,
                                       jacobians ? jacobians[0] : nullptr, nullptr);
  }

 private:
  Intrinsics K_;
  Eigen::Vector3d Xw_;
  Eigen::Matrix<double, kRows, 1> obs_;
  double sqrt_info_;
  const bool* active_;
};

// Bundle adjustment: pose block (7, SE3LeftManifold) and point block (3).
template <int kRows>
class BaCost final : public ceres::SizedCostFunction<kRows, 7, 3> {
 public:
  BaCost(const Intrinsics& K, const Eigen::Matrix<double, kRows, 1>& obs, double inv_sigma2)
      : K_(K), obs_(obs), sqrt_info_(std::sqrt(inv_sigma2)) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return reprojectionResidual<kRows>(K_, parameters[0], Eigen::Map<const Eigen::Vector3d>(parameters[1]),
                                       obs_.data(), sqrt_info_, residuals,
                                       jacobians ? jacobians[0] : nullptr,
                                       jacobians ? jacobians[1] : nullptr);
  }

 private:
  Intrinsics K_;
  Eigen::Matrix<double, kRows, 1> obs_;
  double sqrt_info_;
};

// The residual of one observation: 3 rows (u, v, u_right) with a right coordinate
// (u_right >= 0), else 2 (u, v). The caller (or the problem) owns the result.
inline ceres::CostFunction* newPoseOnlyCost(const Intrinsics& K, const Eigen::Vector3d& Xw,
                                            const Eigen::Vector2d& uv, double u_right, double inv_sigma2,
                                            const bool* active) {
  if (u_right < 0) return new PoseOnlyCost<2>(K, Xw, uv, inv_sigma2, active);
  return new PoseOnlyCost<3>(K, Xw, Eigen::Vector3d(uv.x(), uv.y(), u_right), inv_sigma2, active);
}
inline ceres::CostFunction* newBaCost(const Intrinsics& K, const Eigen::Vector2d& uv, double u_right,
                                      double inv_sigma2) {
  if (u_right < 0) return new BaCost<2>(K, uv, inv_sigma2);
  return new BaCost<3>(K, Eigen::Vector3d(uv.x(), uv.y(), u_right), inv_sigma2);
}

}  // namespace optimization
}  // namespace yolo_slam
