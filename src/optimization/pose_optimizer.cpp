#include "yolo_slam/optimization/pose_optimizer.h"

#include "yolo_slam/optimization/reprojection.h"
#include "yolo_slam/optimization/se3.h"
#include "solver_options.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace yolo_slam {
namespace optimization {

namespace {

// Every observation of the frame in one residual block of Ceres: the problem has a single 6-dof
// parameter, and per-block bookkeeping (one virtual call, validity checks and a manifold
// Jacobian per observation and iteration) cost several times the residuals themselves
// (bench/optimization_bench). The Huber kernel is applied per observation inside: the cost is
// the sum of rho(s) over the squared errors s, as with a HuberLoss per observation. An inactive
// observation contributes 0 with a zero Jacobian (ORB-SLAM2's "level 1" edges).
class StackedPoseCost final : public ceres::CostFunction {
 public:
  StackedPoseCost(const Intrinsics& K, const std::vector<PoseObservation>& obs, const bool* active,
                  const bool* robust)
      : K_(K), obs_(obs), active_(active), robust_(robust) {
    int rows = 0;
    for (const PoseObservation& o : obs) rows += rowsOf(o);
    set_num_residuals(rows);
    mutable_parameter_block_sizes()->push_back(kPoseParams);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    double* jac = jacobians ? jacobians[0] : nullptr;
    int row = 0;
    for (size_t i = 0; i < obs_.size(); ++i) {
      const int n = rowsOf(obs_[i]);
      double* r = residuals + row;
      double* J = jac ? jac + row * kPoseParams : nullptr;
      if (!evaluateOne(parameters[0], i, n, r, J)) return false;
      row += n;
    }
    return true;
  }

 private:
  static int rowsOf(const PoseObservation& o) { return o.u_right >= 0 ? 3 : 2; }

  bool evaluateOne(const double* pose, size_t i, int n, double* r, double* J) const {
    if (!active_[i]) {
      std::fill(r, r + n, 0.0);
      if (J) std::fill(J, J + n * kPoseParams, 0.0);
      return true;
    }
    const PoseObservation& o = obs_[i];
    const double sqrt_info = std::sqrt(o.inv_sigma2);
    bool ok;
    if (n == 3) {
      const double m[3] = {o.uv.x(), o.uv.y(), o.u_right};
      ok = reprojectionResidual<3>(K_, pose, o.Xw, m, sqrt_info, r, J, nullptr);
    } else {
      ok = reprojectionResidual<2>(K_, pose, o.Xw, o.uv.data(), sqrt_info, r, J, nullptr);
    }
    if (ok && *robust_) applyHuber(n, n == 3 ? kChi2Stereo : kChi2Mono, r, J);
    return ok;
  }

  Intrinsics K_;
  const std::vector<PoseObservation>& obs_;
  const bool* active_;
  const bool* robust_;
};

// The prior's 6 residuals: rotation vector of R R_p^T and R (c_p - c) = t - R R_p^T t_p, each
// over its sigma. Under the left update (se3.h) the first moves with d phi as the identity
// (exact at zero deviation), the second as Exp(phi) e + rho.
class PosePriorCost final : public ceres::SizedCostFunction<6, kPoseParams> {
 public:
  explicit PosePriorCost(const PosePrior& p) : prior_(p) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Pose T = paramsToPose(parameters[0]);
    const Eigen::Matrix3d dR = T.linear() * prior_.T_cw.linear().transpose();
    const Eigen::Vector3d e_rot = logSO3(dR);
    const Eigen::Vector3d e_t = T.translation() - dR * prior_.T_cw.translation();
    const double wr = 1.0 / prior_.sigma_rad, wt = 1.0 / prior_.sigma_m;
    Eigen::Map<Eigen::Matrix<double, 6, 1>> r(residuals);
    r << wr * e_rot, wt * e_t;
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 6, kPoseParams, Eigen::RowMajor>> J(jacobians[0]);
      J.setZero();
      J.block<3, 3>(0, 0) = wr * Eigen::Matrix3d::Identity();
      J.block<3, 3>(3, 0) = -wt * skew(e_t);
      J.block<3, 3>(3, 3) = wt * Eigen::Matrix3d::Identity();
    }
    return true;
  }

 private:
  PosePrior prior_;
};

bool usable(const PoseObservation& o) {
  return o.Xw.allFinite() && o.uv.allFinite() && std::isfinite(o.u_right) &&
         std::isfinite(o.inv_sigma2) && o.inv_sigma2 > 0;
}

// ORB-SLAM2 PoseOptimization: observations needed at all, Levenberg-Marquardt iterations per
// round, and the inliers below which the rounds stop.
constexpr int kMinObservations = 3;
constexpr int kIterationsPerRound = 10;
constexpr int kMinActive = 10;

// Re-classifies every observation at the current pose (unusable ones stay outliers); returns
// the outliers, n_active the inliers.
int classify(const Intrinsics& K, const double* pose, const std::vector<PoseObservation>& obs,
             std::vector<bool>& is_outlier, bool* active, int* n_active) {
  int n_bad = 0;
  *n_active = 0;
  for (size_t i = 0; i < obs.size(); ++i) {
    if (!usable(obs[i])) {
      ++n_bad;
      continue;
    }
    const PoseObservation& o = obs[i];
    ReprojectionCheck c = checkReprojection(K, pose, o.Xw, o.uv, o.u_right, o.inv_sigma2);
    const bool bad = !(c.chi2 <= chi2Threshold(o.u_right)) || !(c.depth > 0);
    is_outlier[i] = bad;
    active[i] = !bad;
    n_bad += bad ? 1 : 0;
    *n_active += bad ? 0 : 1;
  }
  return n_bad;
}

}  // namespace

int optimizePose(const CameraModel& cam, Pose& T_cw, const std::vector<PoseObservation>& obs,
                 std::vector<bool>& is_outlier, int rounds, const PosePrior* prior) {
  const size_t n = obs.size();
  is_outlier.assign(n, false);
  int n_usable = 0;
  for (size_t i = 0; i < n; ++i) {
    if (usable(obs[i])) {
      ++n_usable;
    } else {
      is_outlier[i] = true;
    }
  }
  if (n_usable < kMinObservations || rounds < 1 || !T_cw.matrix().allFinite()) return 0;

  const Intrinsics K = Intrinsics::from(cam);
  double pose[kPoseParams];
  poseToParams(T_cw, pose);

  std::unique_ptr<bool[]> active(new bool[n]);
  for (size_t i = 0; i < n; ++i) active[i] = !is_outlier[i];
  bool robust = true;
  StackedPoseCost cost(K, obs, active.get(), &robust);
  SE3LeftManifold manifold;

  ceres::Problem::Options popts;
  popts.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(popts);
  problem.AddParameterBlock(pose, kPoseParams, &manifold);
  problem.AddResidualBlock(&cost, nullptr, pose);
  std::unique_ptr<PosePriorCost> prior_cost;
  if (prior && prior->T_cw.matrix().allFinite() && prior->sigma_m > 0 && prior->sigma_rad > 0) {
    prior_cost = std::make_unique<PosePriorCost>(*prior);
    problem.AddResidualBlock(prior_cost.get(), nullptr, pose);
  }

  const ceres::Solver::Options sopts = solverOptions(ceres::DENSE_NORMAL_CHOLESKY, kIterationsPerRound);
  int n_bad = 0;
  for (int round = 0; round < rounds; ++round) {
    ceres::Solver::Summary summary;
    ceres::Solve(sopts, &problem, &summary);
    int n_active = 0;
    n_bad = classify(K, pose, obs, is_outlier, active.get(), &n_active);
    if (round == rounds - 2) robust = false;
    if (n_active < kMinActive) break;
  }

  Pose result = paramsToPose(pose);
  if (!result.matrix().allFinite()) return 0;
  T_cw = result;
  return static_cast<int>(n) - n_bad;
}

}  // namespace optimization
}  // namespace yolo_slam
