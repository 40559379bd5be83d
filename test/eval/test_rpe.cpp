#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/eval/rpe.h"
#include "yolo_slam/io/trajectory.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

namespace {

// n poses 0.1 s apart; pose k = motion^k.
Trajectory chain(const Pose& motion, int n, double t0 = 0.0) {
  Trajectory t;
  Pose T = Pose::Identity();
  for (int k = 0; k < n; ++k) {
    StampedPose p;
    p.stamp = t0 + 0.1 * k;
    p.T_wc = T;
    t.push_back(p);
    T = T * motion;
  }
  return t;
}

Pose translation(double x) {
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(x, 0, 0);
  return T;
}

Pose yaw(double deg) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

}  // namespace

TEST(Rpe, FindClosestIndexLikeTheScript) {
  std::vector<double> L{0, 1, 2, 3};
  EXPECT_EQ(eval::findClosestIndex(L, 1.6), 2u);
  EXPECT_EQ(eval::findClosestIndex(L, 1.4), 1u);
  EXPECT_EQ(eval::findClosestIndex(L, 2.0), 2u);
  EXPECT_EQ(eval::findClosestIndex(L, -5), 0u);
  EXPECT_EQ(eval::findClosestIndex(L, 9), 3u);
  // Tie: the script keeps the first strictly closer element on its search path.
  EXPECT_EQ(eval::findClosestIndex({0, 1, 2}, 0.5), 0u);
  EXPECT_EQ(eval::findClosestIndex({0, 1, 2}, 1.5), 1u);
}

TEST(Rpe, ZeroForIdenticalTrajectories) {
  Trajectory gt = chain(translation(0.1) * yaw(2), 30);
  eval::RpeResult r = eval::computeRpe(gt, gt);
  EXPECT_GT(r.pairs.size(), 10u);
  EXPECT_LT(r.trans.max, 1e-12);
  EXPECT_LT(r.rot_deg.max, 1e-6);
}

TEST(Rpe, TranslationalDriftPerFrameAndPerSecond) {
  const int n = 30;
  Trajectory gt = chain(translation(0.10), n);   // 1 m/s
  Trajectory est = chain(translation(0.11), n);  // 10 % too fast: 0.01 m per frame
  eval::RpeOptions f;
  f.unit = eval::DeltaUnit::Frames;
  eval::RpeResult r = eval::computeRpe(gt, est, f);
  EXPECT_EQ(r.trans.count, size_t(n - 2));  // (i, i+1), except the pair ending at the last pose
  EXPECT_NEAR(r.trans.rmse, 0.01, 1e-12);
  EXPECT_NEAR(r.trans.std, 0.0, 1e-12);
  EXPECT_NEAR(r.rot_deg.max, 0.0, 1e-9);
  eval::RpeResult s = eval::computeRpe(gt, est);  // default: 1 s = 10 frames
  EXPECT_EQ(s.trans.count, size_t(n - 11));
  EXPECT_NEAR(s.trans.mean, 0.1, 1e-9);
  EXPECT_NEAR(s.max_time_diff, 0.2, 1e-9);  // 2 x median gt interval
}

TEST(Rpe, RotationalDrift) {
  Trajectory gt = chain(yaw(1.0), 20);
  Trajectory est = chain(yaw(1.5), 20);
  eval::RpeOptions f;
  f.unit = eval::DeltaUnit::Frames;
  f.delta = 2;
  eval::RpeResult r = eval::computeRpe(gt, est, f);
  EXPECT_EQ(r.rot_deg.count, 17u);  // i + 2 <= 18
  EXPECT_NEAR(r.rot_deg.rmse, 1.0, 1e-6);
  EXPECT_NEAR(r.rot_deg.median, 1.0, 1e-6);
  EXPECT_NEAR(r.trans.max, 0.0, 1e-12);
}

TEST(Rpe, ErrorComposedAsTheScript) {
  // gt moves 1 m along x and turns 90 degrees per frame; the estimate only translates.
  // evaluate_rpe.py's E = (inv(est_i) est_j) inv(inv(gt_i) gt_j) has translation (1, 1, 0);
  // the paper's inv(inv(gt_i) gt_j) (inv(est_i) est_j) would give 0.
  Trajectory gt = chain(translation(1.0) * yaw(90), 5);
  Trajectory est = chain(translation(1.0), 5);
  eval::RpeOptions f;
  f.unit = eval::DeltaUnit::Frames;
  eval::RpeResult r = eval::computeRpe(gt, est, f);
  ASSERT_EQ(r.pairs.size(), 3u);
  EXPECT_NEAR(r.trans.mean, std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(r.rot_deg.mean, 90.0, 1e-9);
}

TEST(Rpe, StampMatchingAndErrors) {
  Trajectory gt = chain(translation(0.1), 30);
  // Estimate stamps 5 ms late: matched to the nearest gt stamp.
  Trajectory est = chain(translation(0.1), 30, 0.005);
  eval::RpeResult r = eval::computeRpe(gt, est);
  EXPECT_EQ(r.pairs.front().gt_stamp0, 0.0);
  EXPECT_NEAR(r.trans.max, 0.0, 1e-12);
  // A 1 ms max difference rejects every pair.
  eval::RpeOptions tight;
  tight.max_time_diff = 0.001;
  EXPECT_THROW(eval::computeRpe(gt, est, tight), Error);
  EXPECT_THROW(eval::computeRpe(gt, chain(translation(0.1), 30, 100.0)), Error);  // no overlap
  EXPECT_THROW(eval::computeRpe(gt, Trajectory(est.begin(), est.begin() + 1)), Error);
  EXPECT_THROW(eval::computeRpe({}, est), Error);
  eval::RpeOptions bad;
  bad.delta = 0;
  EXPECT_THROW(eval::computeRpe(gt, est, bad), Error);
  EXPECT_THROW(eval::parseDeltaUnit("m"), Error);
  EXPECT_EQ(eval::parseDeltaUnit("f"), eval::DeltaUnit::Frames);
}

// Values cross-checked against an independent numpy implementation of evaluate_rpe.py
// --fixed_delta (agreement to 9 significant digits).
TEST(Rpe, RealReferenceTrajectories) {
  const std::string dir = joinPath(sharedDir(), "data/reference_trajectories");
  Trajectory gt = io::readTrajectory(joinPath(dir, "fr3_walking_xyz_groundtruth.txt"));
  Trajectory est = io::readTrajectory(joinPath(dir, "fr3_walking_xyz_dynaslam_estimate.txt"));
  eval::RpeOptions f;
  f.unit = eval::DeltaUnit::Frames;
  eval::RpeResult r = eval::computeRpe(gt, est, f);
  EXPECT_EQ(r.trans.count, 755u);
  EXPECT_NEAR(r.trans.rmse, 0.0125345517, 1e-6);
  EXPECT_NEAR(r.rot_deg.rmse, 0.39847311, 1e-5);
  eval::RpeResult s = eval::computeRpe(gt, est);
  EXPECT_EQ(s.trans.count, 728u);
  EXPECT_NEAR(s.trans.rmse, 0.0218091819, 1e-6);
  EXPECT_NEAR(s.rot_deg.rmse, 0.618396895, 1e-5);
}
