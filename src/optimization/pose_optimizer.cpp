#include "yolo_slam/optimization/pose_optimizer.h"

#include "yolo_slam/optimization/reprojection.h"
#include "yolo_slam/optimization/se3.h"

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
  if (n_usable < 3 || rounds < 1 || !T_cw.matrix().allFinite()) return 0;

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
    if (o.u_right >= 0) {
      costs.emplace_back(new PoseOnlyCost<3>(K, o.Xw, Eigen::Vector3d(o.uv.x(), o.uv.y(), o.u_right),
                                             o.inv_sigma2, &active[i]));
      problem.AddResidualBlock(costs.back().get(), &loss_stereo, pose);
    } else {
      costs.emplace_back(new PoseOnlyCost<2>(K, o.Xw, o.uv, o.inv_sigma2, &active[i]));
      problem.AddResidualBlock(costs.back().get(), &loss_mono, pose);
    }
  }

  ceres::Solver::Options sopts;
  sopts.linear_solver_type = ceres::DENSE_QR;
  sopts.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  sopts.max_num_iterations = 10;
  sopts.num_threads = 1;
  sopts.logging_type = ceres::SILENT;
  sopts.minimizer_progress_to_stdout = false;

  int n_bad = 0;
  for (int round = 0; round < rounds; ++round) {
    ceres::Solver::Summary summary;
    ceres::Solve(sopts, &problem, &summary);

    n_bad = 0;
    int n_active = 0;
    for (size_t i = 0; i < n; ++i) {
      if (!usable(obs[i])) {
        ++n_bad;
        continue;
      }
      const PoseObservation& o = obs[i];
      ReprojectionCheck c = checkReprojection(K, pose, o.Xw, o.uv, o.u_right, o.inv_sigma2);
      const double th = o.u_right >= 0 ? kChi2Stereo : kChi2Mono;
      const bool bad = !(c.chi2 <= th) || !(c.depth > 0);
      is_outlier[i] = bad;
      active[i] = !bad;
      n_bad += bad ? 1 : 0;
      n_active += bad ? 0 : 1;
    }
    if (round == rounds - 2) robust = false;
    if (n_active < 10) break;
  }

  Pose result = paramsToPose(pose);
  if (!result.matrix().allFinite()) return 0;
  T_cw = result;
  return static_cast<int>(n) - n_bad;
}

}  // namespace optimization
}  // namespace yolo_slam
