#include "yolo_slam/optimization/reprojection.h"

#include "yolo_slam/common/geometry.h"

#include <Eigen/Geometry>

#include <cmath>
#include <limits>

namespace yolo_slam {
namespace optimization {

template <int kRows>
bool reprojectionResidual(const Intrinsics& K, const double* pose, const Eigen::Vector3d& Xw,
                          const double* obs, double sqrt_info, double* residuals,
                          double* jac_pose, double* jac_point) {
  Eigen::Map<const Eigen::Quaterniond> q(pose);
  Eigen::Map<const Eigen::Vector3d> t(pose + 4);
  const Eigen::Matrix3d R = q.toRotationMatrix();
  const Eigen::Vector3d pc = R * Xw + t;
  const double z = pc.z();
  if (std::abs(z) < 1e-10) return false;
  const double iz = 1.0 / z;
  const double xz = pc.x() * iz, yz = pc.y() * iz;
  residuals[0] = sqrt_info * (K.fx * xz + K.cx - obs[0]);
  residuals[1] = sqrt_info * (K.fy * yz + K.cy - obs[1]);
  if (kRows == 3) residuals[2] = sqrt_info * (K.fx * xz + K.cx - K.bf * iz - obs[2]);
  if (!jac_pose && !jac_point) return true;

  // d residual / d p_c.
  Eigen::Matrix<double, kRows, 3> Jp;
  Jp.row(0) << K.fx * iz, 0.0, -K.fx * xz * iz;
  Jp.row(1) << 0.0, K.fy * iz, -K.fy * yz * iz;
  if (kRows == 3) Jp.row(kRows - 1) << K.fx * iz, 0.0, (-K.fx * xz + K.bf * iz) * iz;
  Jp *= sqrt_info;

  if (jac_pose) {
    // p_c' = Exp(phi) p_c + rho  ->  d p_c / d [phi rho] = [-[p_c]x  I]
    Eigen::Map<Eigen::Matrix<double, kRows, 7, Eigen::RowMajor>> J(jac_pose);
    J.template leftCols<3>() = -Jp * skew(pc);
    J.template middleCols<3>(3) = Jp;
    J.col(6).setZero();
  }
  if (jac_point) {
    Eigen::Map<Eigen::Matrix<double, kRows, 3, Eigen::RowMajor>> J(jac_point);
    J = Jp * R;
  }
  return true;
}

template bool reprojectionResidual<2>(const Intrinsics&, const double*, const Eigen::Vector3d&,
                                      const double*, double, double*, double*, double*);
template bool reprojectionResidual<3>(const Intrinsics&, const double*, const Eigen::Vector3d&,
                                      const double*, double, double*, double*, double*);

ReprojectionCheck checkReprojection(const Intrinsics& K, const double* pose,
                                    const Eigen::Vector3d& Xw, const Eigen::Vector2d& uv,
                                    double u_right, double inv_sigma2) {
  Eigen::Map<const Eigen::Quaterniond> q(pose);
  Eigen::Map<const Eigen::Vector3d> t(pose + 4);
  const Eigen::Vector3d pc = q * Xw + t;
  ReprojectionCheck c{0.0, pc.z()};
  if (!(std::abs(pc.z()) >= 1e-10)) {
    c.chi2 = std::numeric_limits<double>::infinity();
    return c;
  }
  const double iz = 1.0 / pc.z();
  const double u = K.fx * pc.x() * iz + K.cx, v = K.fy * pc.y() * iz + K.cy;
  double e2 = (u - uv.x()) * (u - uv.x()) + (v - uv.y()) * (v - uv.y());
  if (u_right >= 0) {
    const double ur = u - K.bf * iz;
    e2 += (ur - u_right) * (ur - u_right);
  }
  c.chi2 = e2 * inv_sigma2;
  return c;
}

}  // namespace optimization
}  // namespace yolo_slam
