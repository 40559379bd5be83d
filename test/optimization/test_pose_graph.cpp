#include "yolo_slam/common/error.h"
#include "yolo_slam/optimization/pose_graph.h"
#include "yolo_slam/optimization/se3.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

using namespace yolo_slam;
using namespace yolo_slam::optimization;

namespace {

// 30 poses on a circle of radius 2 m looking outwards; odometry with a systematic yaw bias and
// noise accumulates drift; one loop edge (last -> first) measured exactly.
struct Loop {
  std::map<long, Pose> truth, estimate;
  std::vector<PoseGraphEdge> edges;
};

Loop makeLoop() {
  Loop l;
  const int n = 30;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    Pose T = Pose::Identity();
    T.linear() = expSO3(Eigen::Vector3d(0, a, 0));
    T.translation() = Eigen::Vector3d(2.0 * std::sin(a), 0.1 * std::sin(3 * a), 2.0 * std::cos(a));
    l.truth[i] = T;
  }
  std::mt19937 gen(17);
  std::normal_distribution<double> nz(0.0, 1.0);
  l.estimate[0] = l.truth[0];
  for (int i = 0; i + 1 < n; ++i) {
    Pose rel = l.truth[i].inverse() * l.truth[i + 1];
    Pose noisy = rel;
    noisy.linear() = expSO3(Eigen::Vector3d(0.002 * nz(gen), 0.01 + 0.002 * nz(gen), 0.002 * nz(gen))) * rel.linear();
    noisy.translation() += 0.01 * Eigen::Vector3d(nz(gen), nz(gen), nz(gen));
    l.edges.push_back({i, i + 1, noisy, 1.0});
    l.estimate[i + 1] = l.estimate[i] * noisy;
  }
  l.edges.push_back({n - 1, 0, l.truth[n - 1].inverse() * l.truth[0], 10.0});
  return l;
}

double maxPositionError(const Loop& l) {
  double e = 0;
  for (const auto& kv : l.truth) {
    e = std::max(e, (l.estimate.at(kv.first).translation() - kv.second.translation()).norm());
  }
  return e;
}

}  // namespace

TEST(PoseGraph, ClosesSyntheticLoop) {
  Loop l = makeLoop();
  l.estimate[99] = Pose::Identity();  // a node without edges is left alone
  l.estimate[99].translation() = Eigen::Vector3d(5, 5, 5);
  const double before = maxPositionError(l);
  ASSERT_GT(before, 0.3);  // the drift is real
  const Pose node0 = l.estimate[0];
  PoseGraphResult r = optimizePoseGraph(l.estimate, l.edges, {0}, 50);
  const double after = maxPositionError(l);
  std::printf("max position error %.3f m -> %.3f m, cost %.3g -> %.3g in %d iterations\n", before, after,
              r.initial_cost, r.final_cost, r.iterations);
  EXPECT_LT(after, 0.2 * before) << before << " -> " << after;
  EXPECT_LT(after, 0.1);  // the 1 cm/step odometry noise alone leaves a few cm
  EXPECT_LT(r.final_cost, 0.01 * r.initial_cost);
  EXPECT_GT(r.iterations, 0);
  EXPECT_TRUE(l.estimate[0].isApprox(node0, 0.0));
  EXPECT_EQ(l.estimate[99].translation(), Eigen::Vector3d(5, 5, 5));
  // The loop edge now holds: last -> first matches its measurement.
  Pose E = l.edges.back().T_from_to.inverse() * (l.estimate[29].inverse() * l.estimate[0]);
  EXPECT_LT(E.translation().norm(), 0.02);
  EXPECT_LT(rotationAngle(E.linear()), 0.01);
}

TEST(PoseGraph, BadGraphsAreErrors) {
  Loop l = makeLoop();
  std::vector<PoseGraphEdge> edges = l.edges;
  edges.push_back({0, 1234, Pose::Identity(), 1.0});
  EXPECT_THROW(optimizePoseGraph(l.estimate, edges, {0}), Error);
  edges = l.edges;
  edges[0].weight = 0;
  EXPECT_THROW(optimizePoseGraph(l.estimate, edges, {0}), Error);
  std::map<long, Pose> empty;
  PoseGraphResult r = optimizePoseGraph(empty, {}, {});
  EXPECT_EQ(r.iterations, 0);
}
