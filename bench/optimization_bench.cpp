// Timing of the Ceres building blocks on synthetic data (fixed seeds):
//   pose-only optimisation with N observations (default 300, 20% outliers, 60% with depth),
//   local bundle adjustment of a 10-keyframe window (3 fixed) with 2000 points, and of wide
//   windows (40, 80, 120 free keyframes, 3000 points seen by 10 keyframes each).
// Usage: optimization_bench [n_observations] [runs]
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/optimization/bundle_adjustment.h"
#include "yolo_slam/optimization/pose_optimizer.h"
#include "yolo_slam/optimization/se3.h"

#include <cstdio>
#include <cstdlib>
#include <random>

using namespace yolo_slam;
using namespace yolo_slam::optimization;

namespace {

// Local BA of n_kf keyframes (the first n_fixed held) and n_points points; each point is seen
// by the keyframes k with (j + k) % 3 != 0, or by `views` consecutive keyframes when views > 0.
void benchLocalBa(const CameraModel& cam, int n_kf, int n_fixed, int n_points, int views) {
  std::vector<double> t_ba;
  BaResult res;
  size_t n_obs = 0;
  for (int r = 0; r < 5; ++r) {
    std::mt19937 g2(11);
    std::normal_distribution<double> n2(0.0, 1.0);
    std::uniform_real_distribution<double> uu(20, 620), vv(20, 460), dd(0.8, 6.0);
    BaProblem p;
    std::vector<Pose> truth;
    const double step = 1.0 / n_kf;  // the path is 1 m long whatever the window
    for (int k = 0; k < n_kf; ++k) {
      Pose T = Pose::Identity();
      T.translation() = Eigen::Vector3d(-step * k, 0.2 * step * k, 0);
      truth.push_back(T);
      Pose Tp = T;
      if (k >= n_fixed) Tp.translation() += 0.01 * Eigen::Vector3d(n2(g2), n2(g2), n2(g2));
      p.keyframes.push_back({k, Tp, k < n_fixed});
    }
    for (int j = 0; j < n_points; ++j) {
      Eigen::Vector3d X = cam.unproject(uu(g2), vv(g2), dd(g2));
      p.points.push_back({j, X + 0.02 * Eigen::Vector3d(n2(g2), n2(g2), n2(g2))});
      const int first = views > 0 ? j % std::max(1, n_kf - views + 1) : 0;
      for (int k = first; k < (views > 0 ? first + views : n_kf); ++k) {
        if (views == 0 && (j + k) % 3 == 0) continue;  // each point seen by ~2/3 of the window
        Eigen::Vector3d pc = truth[k] * X;
        if (pc.z() <= 0.1) continue;
        Eigen::Vector2d uv = cam.project(pc) + Eigen::Vector2d(n2(g2), n2(g2));
        if (!cam.inImage(uv.x(), uv.y())) continue;
        BaObservation o{k, j, uv};
        if (j % 2 == 0) o.u_right = uv.x() - cam.bf / pc.z();
        p.observations.push_back(o);
      }
    }
    n_obs = p.observations.size();
    Stopwatch sw;
    res = localBundleAdjustment(cam, p);
    t_ba.push_back(sw.ms());
  }
  Summary sb = summarize(t_ba);
  std::printf("localBundleAdjustment: %d keyframes (%d fixed), %d points, %zu observations, %d iterations, "
              "cost %.1f -> %.1f: median %.1f ms (5 runs)\n",
              n_kf, n_fixed, n_points, n_obs, res.iterations, res.initial_cost, res.final_cost, sb.median);
}

}  // namespace

int main(int argc, char** argv) {
  const int n_obs = argc > 1 ? std::atoi(argv[1]) : 300;
  const int runs = argc > 2 ? std::atoi(argv[2]) : 200;
  if (n_obs <= 0 || runs <= 0) {
    std::fprintf(stderr, "error: usage: optimization_bench [n_observations > 0] [runs > 0]\n");
    return 1;
  }
  CameraModel cam;
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> uu(20, 620), vv(20, 460), dd(0.8, 6.0), coin(0, 1);
  std::normal_distribution<double> noise(0.0, 1.0);

  // ---- pose-only ----
  Pose T_true = Pose::Identity();
  T_true.linear() = expSO3(Eigen::Vector3d(0.1, -0.2, 0.05));
  T_true.translation() = Eigen::Vector3d(0.3, -0.1, 0.2);
  std::vector<PoseObservation> obs;
  for (int i = 0; i < n_obs; ++i) {
    Eigen::Vector3d pc = cam.unproject(uu(gen), vv(gen), dd(gen));
    PoseObservation o;
    o.Xw = T_true.inverse() * pc;
    Eigen::Vector2d uv = cam.project(pc);
    const bool outlier = i % 5 == 0;
    o.uv = outlier ? Eigen::Vector2d(uu(gen), vv(gen)) : uv + Eigen::Vector2d(noise(gen), noise(gen));
    // The right coordinate's noise comes from the depth, independent of u's.
    if (coin(gen) < 0.6) o.u_right = (outlier ? o.uv.x() : uv.x() + noise(gen)) - cam.bf / pc.z();
    obs.push_back(o);
  }
  Pose T0 = T_true;
  T0.translation() += Eigen::Vector3d(0.03, 0.02, -0.03);
  std::vector<double> t_pose;
  int inliers = 0;
  for (int r = 0; r < runs; ++r) {
    Pose T = T0;
    std::vector<bool> out;
    Stopwatch sw;
    inliers = optimizePose(cam, T, obs, out, 4);
    t_pose.push_back(sw.ms());
  }
  Summary sp = summarize(t_pose);
  std::printf("optimizePose: %d observations, %d inliers, %d runs: median %.3f ms mean %.3f p95 %.3f min %.3f\n",
              n_obs, inliers, runs, sp.median, sp.mean, sp.p95, sp.min);

  benchLocalBa(cam, 10, 3, 2000, 0);
  // Wide windows as in crowded or small-motion sequences: every point seen by 10 consecutive
  // keyframes of many free ones (dense or sparse reduced camera system, bundle_adjustment.cpp).
  for (int n_kf : {40, 80, 120}) benchLocalBa(cam, n_kf + 2, 2, 3000, 10);
  return 0;
}
