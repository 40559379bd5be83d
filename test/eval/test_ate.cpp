#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/eval/ate.h"
#include "yolo_slam/eval/plot.h"
#include "yolo_slam/io/trajectory.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <unistd.h>

using namespace yolo_slam;

namespace {

Pose randomPose(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Quaterniond q(u(rng), u(rng), u(rng), u(rng));
  return makePose(q.normalized(), Eigen::Vector3d(u(rng), u(rng), u(rng)) * 3);
}

// n random poses from stamp t0 at 30 Hz.
Trajectory randomTrajectory(std::mt19937& rng, int n, double t0) {
  Trajectory t;
  for (int k = 0; k < n; ++k) {
    StampedPose p;
    p.stamp = t0 + 0.033 * k;
    p.T_wc = randomPose(rng);
    t.push_back(p);
  }
  return t;
}

Trajectory fromPositions(const std::vector<Eigen::Vector3d>& p, double t0 = 100.0, double dt = 0.1) {
  Trajectory t;
  for (size_t k = 0; k < p.size(); ++k) {
    StampedPose s;
    s.stamp = t0 + dt * k;
    s.T_wc.translation() = p[k];
    t.push_back(s);
  }
  return t;
}

}  // namespace

TEST(ErrorStats, NumpySemantics) {
  eval::ErrorStats s = eval::errorStats({3, 1, 2, 4});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.median, 2.5);  // mean of the two middle values
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population std (ddof 0)
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 4);
  EXPECT_DOUBLE_EQ(eval::errorStats({5, 1, 3}).median, 3);
  EXPECT_EQ(eval::errorStats({}).count, 0u);
}

TEST(AlignRigid, RecoversKnownTransformExactly) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose T = randomPose(rng);
    std::vector<Eigen::Vector3d> model, data;
    std::uniform_real_distribution<double> u(-2, 2);
    for (int k = 0; k < 50; ++k) {
      model.emplace_back(u(rng), u(rng), u(rng));
      data.push_back(T * model.back());
    }
    const Pose A = eval::alignRigid(model, data);
    EXPECT_TRUE(A.linear().isApprox(T.linear(), 1e-12)) << trial;
    EXPECT_TRUE(A.translation().isApprox(T.translation(), 1e-12)) << trial;
    EXPECT_NEAR(A.linear().determinant(), 1.0, 1e-12);
  }
}

TEST(AlignRigid, PlanarPointsGiveRotationNotReflection) {
  // Coplanar points: the cross-covariance is rank 2 and the SVD may return a reflection; the
  // det fix must still give the true rotation.
  std::mt19937 rng(5);
  const Pose T = randomPose(rng);
  std::vector<Eigen::Vector3d> model, data;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 4; ++j) {
      model.emplace_back(0.3 * i, -0.2 * j + 0.05 * i * i, 0.0);
      data.push_back(T * model.back());
    }
  }
  const Pose A = eval::alignRigid(model, data);
  EXPECT_NEAR(A.linear().determinant(), 1.0, 1e-12);
  EXPECT_TRUE(A.linear().isApprox(T.linear(), 1e-10));
  EXPECT_TRUE(A.translation().isApprox(T.translation(), 1e-10));
  EXPECT_THROW(eval::alignRigid({Eigen::Vector3d::Zero()}, {Eigen::Vector3d::Zero()}), Error);
  EXPECT_THROW(eval::alignRigid(model, {Eigen::Vector3d::Zero()}), Error);
}

TEST(Ate, ZeroForIdenticalAndRigidlyMovedTrajectories) {
  std::mt19937 rng(11);
  const Trajectory gt = randomTrajectory(rng, 40, 10);
  eval::AteResult r = eval::computeAte(gt, gt);
  EXPECT_EQ(r.stats.count, 40u);
  EXPECT_LT(r.stats.rmse, 1e-12);
  EXPECT_LT(r.stats.max, 1e-12);
  // The estimate in another world frame (as every SLAM run is).
  const Pose W = randomPose(rng);
  Trajectory est = gt;
  for (auto& p : est) p.T_wc = W * p.T_wc;
  r = eval::computeAte(gt, est);
  EXPECT_LT(r.stats.rmse, 1e-12);
  EXPECT_TRUE((r.alignment * W).isApprox(Pose::Identity(), 1e-12));
}

TEST(Ate, KnownValueForConstructedOffset) {
  // Points in +-pairs with the same sign s; est = gt + s d z. Then sum s_k g_k = 0 and sum s_k
  // = 0, so the best rigid alignment is the identity and every error is exactly d.
  const std::vector<Eigen::Vector3d> base{{1, 0.5, 0.2}, {0.3, -1, 0.7}, {-0.4, 0.2, 1.1}, {0.8, 0.9, -0.6}};
  const std::vector<double> sign{1, -1, 1, -1};
  const double d = 0.05;
  std::vector<Eigen::Vector3d> g, e;
  for (size_t k = 0; k < base.size(); ++k) {
    for (double pm : {1.0, -1.0}) {
      g.push_back(pm * base[k]);
      e.push_back(pm * base[k] + sign[k] * d * Eigen::Vector3d::UnitZ());
    }
  }
  std::mt19937 rng(2);
  const Pose W = randomPose(rng);
  for (auto& p : e) p = W * p;
  Trajectory gt = fromPositions(g), est = fromPositions(e, 100.004);  // stamps 4 ms apart
  eval::AteResult r = eval::computeAte(gt, est);
  EXPECT_EQ(r.stats.count, 8u);
  EXPECT_NEAR(r.stats.rmse, d, 1e-12);
  EXPECT_NEAR(r.stats.mean, d, 1e-12);
  EXPECT_NEAR(r.stats.median, d, 1e-12);
  EXPECT_NEAR(r.stats.std, 0, 1e-9);
  EXPECT_NEAR(r.stats.min, d, 1e-12);
  EXPECT_NEAR(r.stats.max, d, 1e-12);
  EXPECT_TRUE((r.alignment * W).isApprox(Pose::Identity(), 1e-12));
  EXPECT_NEAR(r.est_stamps[0] - r.gt_stamps[0], 0.004, 1e-9);
}

TEST(Ate, AssociationDuplicatesAndErrors) {
  std::vector<Eigen::Vector3d> p{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 1}};
  Trajectory gt = fromPositions(p);
  // Estimate only for stamps 2 and 3 plus one 0.05 s off (not associated at 0.02 s).
  Trajectory est = fromPositions(p);
  est[0].stamp += 0.05;
  eval::AteResult r = eval::computeAte(gt, est);
  EXPECT_EQ(r.stats.count, 3u);
  EXPECT_EQ(eval::computeAte(gt, est, 0.06).stats.count, 4u);
  // Duplicate stamps: the later line wins (Python dict), here a pose far away.
  Trajectory dup = gt;
  StampedPose far = gt[1];
  far.T_wc.translation() = Eigen::Vector3d(50, 0, 0);
  dup.push_back(far);
  EXPECT_EQ(eval::uniqueByStamp(dup).size(), 4u);
  EXPECT_GT(eval::computeAte(gt, dup).stats.max, 1.0);
  // No overlap, too little overlap, empty.
  EXPECT_THROW(eval::computeAte(gt, fromPositions(p, 200.0)), Error);
  EXPECT_THROW(eval::computeAte(gt, Trajectory(gt.begin(), gt.begin() + 1)), Error);
  EXPECT_THROW(eval::computeAte(gt, {}), Error);
  EXPECT_THROW(eval::computeAte({}, gt), Error);
}

// Values computed by yolo_slam_eval and cross-checked against an independent numpy
// implementation of evaluate_ate.py (agreement to 9 significant digits).
TEST(Ate, RealReferenceTrajectories) {
  const std::string dir = joinPath(sharedDir(), "data/reference_trajectories");
  Trajectory gt = io::readTrajectory(joinPath(dir, "fr3_walking_xyz_groundtruth.txt"));
  Trajectory est = io::readTrajectory(joinPath(dir, "fr3_walking_xyz_dynaslam_estimate.txt"));
  eval::AteResult r = eval::computeAte(gt, est);
  EXPECT_EQ(r.stats.count, 757u);
  EXPECT_NEAR(r.stats.rmse, 0.0163135333, 1e-6);
  EXPECT_NEAR(r.stats.mean, 0.0138686963, 1e-6);
  EXPECT_NEAR(r.stats.median, 0.0121516557, 1e-6);
  EXPECT_NEAR(r.stats.std, 0.00859014746, 1e-6);
  EXPECT_NEAR(r.stats.max, 0.0572441826, 1e-6);

  Trajectory bgt = io::readTrajectory(joinPath(dir, "bonn_unknown_sequence_groundtruth.txt"));
  Trajectory best = io::readTrajectory(joinPath(dir, "bonn_unknown_sequence_estimate.txt"));
  eval::AteResult b = eval::computeAte(bgt, best);
  EXPECT_EQ(b.stats.count, 357u);
  EXPECT_NEAR(b.stats.rmse, 0.00819817081, 1e-6);

  // The figure renders and is written atomically; bad names write nothing.
  cv::Mat img = eval::renderAtePlot(gt, est, r, "test");
  EXPECT_EQ(img.type(), CV_8UC3);
  EXPECT_GT(img.cols, 500);
  const std::string png = "/tmp/ys_eval_plot_" + std::to_string(::getpid()) + ".png";
  eval::writeAtePlot(png, gt, est, r, "test");
  EXPECT_TRUE(std::ifstream(png).good());
  EXPECT_FALSE(std::ifstream(png + ".tmp").good());
  std::remove(png.c_str());
  EXPECT_THROW(eval::writeAtePlot("/tmp/ys_eval_plot.jpg", gt, est, r, "t"), Error);
  EXPECT_THROW(eval::writeAtePlot("/tmp/ys_no_such_dir/x.png", gt, est, r, "t"), Error);
  EXPECT_FALSE(std::ifstream("/tmp/ys_eval_plot.jpg").good());
}

TEST(Ate, FixedAlignmentIsUsedAsGiven) {
  // A second run in the first run's map frame W: the first run's alignment (W^-1) makes it
  // exact; a wrong map frame shows as an error a fresh alignment would hide.
  std::mt19937 rng(12);
  const Trajectory gt = randomTrajectory(rng, 30, 20);
  const Pose W = randomPose(rng);
  Trajectory est = gt;
  for (auto& p : est) p.T_wc = W * p.T_wc;
  const Pose first_run_alignment = eval::computeAte(gt, est).alignment;
  EXPECT_LT(eval::computeAte(gt, est, 0.02, 0.0, &first_run_alignment).stats.rmse, 1e-9);
  Pose shifted = first_run_alignment;
  shifted.translation() += Eigen::Vector3d(0.1, 0, 0);
  const eval::AteResult off = eval::computeAte(gt, est, 0.02, 0.0, &shifted);
  EXPECT_NEAR(off.stats.rmse, 0.1, 1e-9);
  EXPECT_TRUE(off.alignment.isApprox(shifted, 1e-12));
}

TEST(Ate, HugeCoordinatesAreRefusedNotReportedAsInfinity) {
  Trajectory gt, est;
  for (int i = 0; i < 10; ++i) {
    StampedPose p;
    p.stamp = 1.0 + 0.1 * i;
    p.T_wc = makePose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.1 * i, 0, 1));
    gt.push_back(p);
    if (i == 4) p.T_wc.translation().x() = 1e160;
    est.push_back(p);
  }
  try {
    eval::computeAte(gt, est);
    FAIL() << "an estimate at 1e160 m must not give an rmse";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the estimated pose at stamp 1.400000"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("beyond 1e+09 m"), std::string::npos) << e.what();
  }
  // The plot refuses what it cannot draw instead of stepping through an infinite grid.
  eval::AteResult bad = eval::computeAte(gt, gt);
  bad.stats.max = std::numeric_limits<double>::infinity();
  EXPECT_THROW(eval::renderAtePlot(gt, gt, bad, "t"), Error);
  EXPECT_THROW(eval::renderAtePlot(gt, est, eval::computeAte(gt, gt), "t"), Error);
  EXPECT_EQ(eval::renderAtePlot(gt, gt, eval::computeAte(gt, gt), "t").type(), CV_8UC3);
}
