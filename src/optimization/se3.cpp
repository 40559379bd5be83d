#include "yolo_slam/optimization/se3.h"

#include <cmath>

namespace yolo_slam {
namespace optimization {

Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi) {
  const double theta2 = phi.squaredNorm();
  const Eigen::Matrix3d K = skew(phi);
  if (theta2 < 1e-12) return Eigen::Matrix3d::Identity() + K + 0.5 * K * K;
  const double theta = std::sqrt(theta2);
  return Eigen::Matrix3d::Identity() + (std::sin(theta) / theta) * K +
         ((1.0 - std::cos(theta)) / theta2) * K * K;
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& R) {
  Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

void poseToParams(const Pose& T, double* p) {
  Eigen::Quaterniond q(T.linear());
  q.normalize();
  p[0] = q.x();
  p[1] = q.y();
  p[2] = q.z();
  p[3] = q.w();
  p[4] = T.translation().x();
  p[5] = T.translation().y();
  p[6] = T.translation().z();
}

Pose paramsToPose(const double* p) {
  return makePose(Eigen::Quaterniond(p[3], p[0], p[1], p[2]), Eigen::Vector3d(p[4], p[5], p[6]));
}

bool SE3LeftManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  Eigen::Map<const Eigen::Quaterniond> q(x);
  Eigen::Map<const Eigen::Vector3d> t(x + 4);
  Eigen::Map<const Eigen::Vector3d> phi(delta);
  Eigen::Map<const Eigen::Vector3d> rho(delta + 3);
  // Quaternion of Exp(phi) built directly (half-angle), normalised to stop drift.
  const double theta = phi.norm();
  Eigen::Quaterniond dq;
  if (theta < 1e-10) {
    dq = Eigen::Quaterniond(1.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z());
  } else {
    const double s = std::sin(0.5 * theta) / theta;
    dq = Eigen::Quaterniond(std::cos(0.5 * theta), s * phi.x(), s * phi.y(), s * phi.z());
  }
  Eigen::Quaterniond q_new = (dq * q).normalized();
  Eigen::Vector3d t_new = dq * t + rho;
  Eigen::Map<Eigen::Quaterniond> q_out(x_plus_delta);
  Eigen::Map<Eigen::Vector3d> t_out(x_plus_delta + 4);
  q_out = q_new;
  t_out = t_new;
  return true;
}

bool SE3LeftManifold::PlusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topRows<6>().setIdentity();
  return true;
}

bool SE3LeftManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Map<const Eigen::Quaterniond> qx(x), qy(y);
  Eigen::Map<const Eigen::Vector3d> tx(x + 4), ty(y + 4);
  const Eigen::Matrix3d dR = (qy * qx.conjugate()).normalized().toRotationMatrix();
  Eigen::Map<Eigen::Vector3d> phi(y_minus_x), rho(y_minus_x + 3);
  phi = logSO3(dR);
  rho = ty - dR * tx;
  return true;
}

bool SE3LeftManifold::MinusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.leftCols<6>().setIdentity();
  return true;
}

}  // namespace optimization
}  // namespace yolo_slam
