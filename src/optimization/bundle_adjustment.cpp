#include "yolo_slam/optimization/bundle_adjustment.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/optimization/reprojection.h"
#include "yolo_slam/optimization/se3.h"
#include "solver_options.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <unordered_map>

namespace yolo_slam {
namespace optimization {

namespace {

using StopFn = std::function<bool()>;

class StopCallback final : public ceres::IterationCallback {
 public:
  StopCallback(const StopFn& stop, bool* stopped) : stop_(stop), stopped_(stopped) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    if (stop_ && stop_()) {
      *stopped_ = true;
      // Keep the progress made so far (ORB-SLAM2's force-stop keeps the estimate too).
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }

 private:
  StopFn stop_;
  bool* stopped_;
};

bool usable(const BaObservation& o) {
  return o.uv.allFinite() && std::isfinite(o.u_right) && std::isfinite(o.inv_sigma2) &&
         o.inv_sigma2 > 0;
}

double huber(double s, double th) {
  // rho(s) for Huber with delta^2 = th on the squared error s.
  return s <= th ? s : 2.0 * std::sqrt(s * th) - th;
}

struct Workspace {
  std::vector<std::array<double, kPoseParams>> poses;
  std::vector<std::array<double, 3>> points;
  std::vector<int> obs_kf, obs_pt;  // indices into poses/points per observation
  std::vector<bool> obs_ok;         // usable (finite values)
};

Workspace prepare(const BaProblem& p) {
  Workspace w;
  std::unordered_map<long, int> kf_index, pt_index;
  w.poses.resize(p.keyframes.size());
  for (size_t i = 0; i < p.keyframes.size(); ++i) {
    if (!kf_index.emplace(p.keyframes[i].id, static_cast<int>(i)).second) {
      throw Error("bundle adjustment: keyframe id " + std::to_string(p.keyframes[i].id) +
                  " appears twice in the problem");
    }
    poseToParams(p.keyframes[i].T_cw, w.poses[i].data());
  }
  w.points.resize(p.points.size());
  for (size_t i = 0; i < p.points.size(); ++i) {
    if (!pt_index.emplace(p.points[i].id, static_cast<int>(i)).second) {
      throw Error("bundle adjustment: point id " + std::to_string(p.points[i].id) +
                  " appears twice in the problem");
    }
    for (int k = 0; k < 3; ++k) w.points[i][k] = p.points[i].Xw[k];
  }
  const size_t n = p.observations.size();
  w.obs_kf.resize(n);
  w.obs_pt.resize(n);
  w.obs_ok.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const BaObservation& o = p.observations[i];
    auto kf = kf_index.find(o.kf_id);
    auto pt = pt_index.find(o.point_id);
    if (kf == kf_index.end() || pt == pt_index.end()) {
      throw Error("bundle adjustment: observation " + std::to_string(i) + " refers to " +
                  (kf == kf_index.end() ? "keyframe " + std::to_string(o.kf_id)
                                        : "point " + std::to_string(o.point_id)) +
                  " which is not in the problem");
    }
    w.obs_kf[i] = kf->second;
    w.obs_pt[i] = pt->second;
    const bool finite_state = p.keyframes[kf->second].T_cw.matrix().allFinite() &&
                              p.points[pt->second].Xw.allFinite();
    w.obs_ok[i] = usable(o) && finite_state;
  }
  return w;
}

struct Check {
  double chi2, th, depth;
};

Check check(const Intrinsics& K, const Workspace& w, const BaObservation& o, size_t i) {
  Eigen::Map<const Eigen::Vector3d> X(w.points[w.obs_pt[i]].data());
  ReprojectionCheck c = checkReprojection(K, w.poses[w.obs_kf[i]].data(), X, o.uv, o.u_right, o.inv_sigma2);
  return {c.chi2, chi2Threshold(o.u_right), c.depth};
}

double robustCost(const Intrinsics& K, const Workspace& w, const BaProblem& p) {
  double cost = 0;
  for (size_t i = 0; i < p.observations.size(); ++i) {
    if (!w.obs_ok[i]) continue;
    Check c = check(K, w, p.observations[i], i);
    if (std::isfinite(c.chi2)) cost += 0.5 * huber(c.chi2, c.th);
  }
  return cost;
}

// Points first in the elimination order: the Schur complement leaves a small camera system.
std::shared_ptr<ceres::ParameterBlockOrdering> schurOrdering(Workspace& w, const std::vector<bool>& pose_added,
                                                             const std::vector<bool>& point_added) {
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (size_t j = 0; j < w.points.size(); ++j) {
    if (point_added[j]) ordering->AddElementToGroup(w.points[j].data(), 0);
  }
  for (size_t k = 0; k < w.poses.size(); ++k) {
    if (pose_added[k]) ordering->AddElementToGroup(w.poses[k].data(), 1);
  }
  return ordering;
}

// Above this many free poses the sparse Schur solver beats the dense one: measured with
// optimization_bench (wide windows) and on crowded sequences, whose local windows reach 80 free
// keyframes with every point seen by many of them (BENCHMARKS.md, "Local BA").
constexpr int kMaxDensePoses = 100;

// One Ceres solve over the observations with include[i] set. Returns the iterations used.
int solveStage(const Intrinsics& K, Workspace& w, const BaProblem& p,
               const std::vector<bool>& include, bool robust, int max_iterations,
               const StopFn& stop, bool* stopped) {
  ceres::Problem::Options popts;
  popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(popts);
  SE3LeftManifold manifold;
  ceres::HuberLoss loss_mono(std::sqrt(kChi2Mono)), loss_stereo(std::sqrt(kChi2Stereo));
  std::vector<bool> pose_added(w.poses.size(), false), point_added(w.points.size(), false);
  int n_residuals = 0, n_free_poses = 0;
  for (size_t i = 0; i < p.observations.size(); ++i) {
    if (!include[i]) continue;
    const BaObservation& o = p.observations[i];
    double* pose = w.poses[w.obs_kf[i]].data();
    double* point = w.points[w.obs_pt[i]].data();
    if (!pose_added[w.obs_kf[i]]) {
      problem.AddParameterBlock(pose, kPoseParams, &manifold);
      pose_added[w.obs_kf[i]] = true;
      if (p.keyframes[w.obs_kf[i]].fixed) {
        problem.SetParameterBlockConstant(pose);
      } else {
        ++n_free_poses;
      }
    }
    point_added[w.obs_pt[i]] = true;
    ceres::LossFunction* loss = o.u_right >= 0 ? &loss_stereo : &loss_mono;
    problem.AddResidualBlock(newBaCost(K, o.uv, o.u_right, o.inv_sigma2), robust ? loss : nullptr, pose, point);
    ++n_residuals;
  }
  if (n_residuals == 0 || max_iterations <= 0) return 0;

  // Dense reduced camera matrix is fastest for local windows; large problems go sparse.
  ceres::Solver::Options sopts = solverOptions(
      n_free_poses > kMaxDensePoses && ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)
          ? ceres::SPARSE_SCHUR
          : ceres::DENSE_SCHUR,
      max_iterations);
  sopts.linear_solver_ordering = schurOrdering(w, pose_added, point_added);
  StopCallback callback(stop, stopped);
  if (stop) sopts.callbacks.push_back(&callback);

  ceres::Solver::Summary summary;
  ceres::Solve(sopts, &problem, &summary);
  return std::max(0, static_cast<int>(summary.iterations.size()) - 1);  // entry 0: initial state
}

void writeBack(const Workspace& w, BaProblem& p, const std::vector<bool>& point_observed) {
  for (size_t k = 0; k < p.keyframes.size(); ++k) {
    if (p.keyframes[k].fixed) continue;
    Pose T = paramsToPose(w.poses[k].data());
    if (T.matrix().allFinite()) p.keyframes[k].T_cw = T;
  }
  for (size_t j = 0; j < p.points.size(); ++j) {
    if (!point_observed[j]) continue;
    Eigen::Vector3d X(w.points[j][0], w.points[j][1], w.points[j][2]);
    if (X.allFinite()) p.points[j].Xw = X;
  }
}

BaResult runBa(const CameraModel& cam, BaProblem& p, int first_iterations, int second_iterations,
               const StopFn& stop) {
  const Intrinsics K = Intrinsics::from(cam);
  Workspace w = prepare(p);
  const size_t n = p.observations.size();
  BaResult res;
  res.initial_cost = robustCost(K, w, p);

  // Observations whose point is at or behind the camera at the start cannot be evaluated
  // safely (the projection blows up); they start excluded and are re-tested at the end.
  std::vector<bool> include(n, false);
  for (size_t i = 0; i < n; ++i) {
    if (!w.obs_ok[i]) continue;
    include[i] = check(K, w, p.observations[i], i).depth > 0;
  }
  std::vector<bool> point_observed(w.points.size(), false);
  for (size_t i = 0; i < n; ++i) {
    if (include[i]) point_observed[w.obs_pt[i]] = true;
  }

  bool stopped = stop && stop();
  if (!stopped) {
    res.iterations += solveStage(K, w, p, include, true, first_iterations, stop, &stopped);
  }
  if (!stopped && second_iterations > 0) {
    for (size_t i = 0; i < n; ++i) {
      if (!include[i]) continue;
      Check c = check(K, w, p.observations[i], i);
      include[i] = c.chi2 <= c.th && c.depth > 0;
    }
    res.iterations += solveStage(K, w, p, include, false, second_iterations, stop, &stopped);
  }
  res.stopped = stopped;

  res.outlier_observation.assign(n, true);
  std::vector<bool> point_supported(w.points.size(), false);
  for (size_t i = 0; i < n; ++i) {
    if (!w.obs_ok[i]) continue;
    Check c = check(K, w, p.observations[i], i);
    res.outlier_observation[i] = !(c.chi2 <= c.th) || !(c.depth > 0);
    if (!res.outlier_observation[i]) point_supported[w.obs_pt[i]] = true;
  }
  // A point whose observations all ended as outliers was pulled by inconsistent measurements
  // (it can run off far along its rays); keep its old position, the caller culls it anyway.
  for (size_t j = 0; j < w.points.size(); ++j) {
    if (point_observed[j] && !point_supported[j]) {
      for (int k = 0; k < 3; ++k) w.points[j][k] = p.points[j].Xw[k];
      point_observed[j] = false;
    }
  }
  res.final_cost = robustCost(K, w, p);
  writeBack(w, p, point_observed);
  return res;
}

// Iterations of the two stages of local BA (ORB-SLAM2 LocalBundleAdjustment: 5 robust, then 10
// without the kernel and the outliers).
constexpr int kLocalRobustIterations = 5;
constexpr int kLocalRefineIterations = 10;

}  // namespace

BaResult localBundleAdjustment(const CameraModel& cam, BaProblem& problem, const bool* stop_flag) {
  StopFn stop;
  if (stop_flag) stop = [stop_flag] { return __atomic_load_n(stop_flag, __ATOMIC_ACQUIRE); };
  return runBa(cam, problem, kLocalRobustIterations, kLocalRefineIterations, stop);
}

BaResult localBundleAdjustment(const CameraModel& cam, BaProblem& problem,
                               const std::atomic<bool>& stop_flag) {
  return runBa(cam, problem, kLocalRobustIterations, kLocalRefineIterations,
               [&stop_flag] { return stop_flag.load(); });
}

BaResult globalBundleAdjustment(const CameraModel& cam, BaProblem& problem, int iterations) {
  return runBa(cam, problem, std::max(0, iterations), 0, StopFn());
}

BaResult globalBundleAdjustment(const CameraModel& cam, BaProblem& problem, int iterations,
                                const std::atomic<bool>& stop_flag) {
  return runBa(cam, problem, std::max(0, iterations), 0, [&stop_flag] { return stop_flag.load(); });
}

}  // namespace optimization
}  // namespace yolo_slam
