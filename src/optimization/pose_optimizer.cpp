#include "yolo_slam/optimization/pose_optimizer.h"

#include "yolo_slam/optimization/reprojection.h"
#include "yolo_slam/optimization/se3.h"
#include "solver_options.h"

#include <ceres/ceres.h>

#include <cmath>
#include <memory>

namespace yolo_slam {
namespace optimization {

namespace {

// Huber that can be switched to plain least squares between rounds without rebuilding the
// problem (ORB-SLAM2 removes the kernel for the last round).
class SwitchableHuber final : public ceres::LossFunction {
 public:
  SwitchableHuber(double delta, const bool* robust) : huber_(delta), robust_(robust) {}
  void Evaluate(double s, double rho[3]) const override {
    if (*robust_) {
      huber_.Evaluate(s, rho);
    } else {
      rho[0] = s;
      rho[1] = 1.0;
      rho[2] = 0.0;
    }
  }

 private:
  ceres::HuberLoss huber_;
  const bool* robust_;
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
                 std::vector<bool>& is_outlier, int rounds) {
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

  // Cost and loss functions live here; the problem only borrows them.
  std::unique_ptr<bool[]> active(new bool[n]);
  bool robust = true;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  costs.reserve(n_usable);
  SwitchableHuber loss_mono(std::sqrt(kChi2Mono), &robust);
  SwitchableHuber loss_stereo(std::sqrt(kChi2Stereo), &robust);
  SE3LeftManifold manifold;

  ceres::Problem::Options popts;
  popts.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(popts);
  problem.AddParameterBlock(pose, kPoseParams, &manifold);
  for (size_t i = 0; i < n; ++i) {
    active[i] = !is_outlier[i];
    if (is_outlier[i]) continue;
    const PoseObservation& o = obs[i];
    costs.emplace_back(newPoseOnlyCost(K, o.Xw, o.uv, o.u_right, o.inv_sigma2, &active[i]));
    problem.AddResidualBlock(costs.back().get(), o.u_right >= 0 ? &loss_stereo : &loss_mono, pose);
  }

  const ceres::Solver::Options sopts = solverOptions(ceres::DENSE_QR, kIterationsPerRound);
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
