// The mean-velocity prediction (slam/motion_model.h): the fractional step, and how far one
// dragged frame moves the prediction with the last step alone and with the mean of four.
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/slam/motion_model.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace yolo_slam;

namespace {

Pose makePose(const Eigen::Vector3d& axis_angle, const Eigen::Vector3d& t) {
  Pose T = Pose::Identity();
  if (axis_angle.norm() > 0) T.linear() = Eigen::AngleAxisd(axis_angle.norm(), axis_angle.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

// A camera moving 1 cm and turning 0.5 degrees per frame.
const Pose kStep = makePose(Eigen::Vector3d(0.002, 0.008, -0.001), Eigen::Vector3d(0.01, -0.002, 0.003));
constexpr size_t kCapacity = 5;

// Four poses of a camera moving at kStep; the newest in `newest`.
slam::MotionHistory steadyHistory(Pose& newest) {
  slam::MotionHistory h;
  newest = Pose::Identity();
  h.push(newest, kCapacity);
  for (int i = 0; i < 3; ++i) {
    newest = kStep * newest;
    h.push(newest, kCapacity);
  }
  return h;
}

}  // namespace

TEST(MotionModel, FractionalStepRepeatedGivesTheWholeMotion) {
  const Pose V = makePose(Eigen::Vector3d(0.1, -0.3, 0.2), Eigen::Vector3d(0.2, 0.05, -0.1));
  for (int k = 1; k <= 5; ++k) {
    const Pose S = slam::fractionalStep(V, k);
    Pose P = Pose::Identity();
    for (int i = 0; i < k; ++i) P = S * P;
    EXPECT_TRUE(P.matrix().isApprox(V.matrix(), 1e-12)) << "k " << k;
  }
  EXPECT_TRUE(slam::fractionalStep(Pose::Identity(), 4).matrix().isApprox(Pose::Identity().matrix()));
}

TEST(MotionModel, NeedsTwoPosesAndKeepsItsCapacity) {
  slam::MotionHistory h;
  EXPECT_FALSE(h.meanStep(4).has_value());
  h.push(Pose::Identity(), kCapacity);
  EXPECT_FALSE(h.meanStep(4).has_value());
  Pose T = Pose::Identity();
  for (int i = 0; i < 9; ++i) {
    T = kStep * T;
    h.push(T, kCapacity);
  }
  EXPECT_EQ(h.size(), kCapacity);
  // Constant velocity: the mean of any number of steps is the step.
  for (int steps = 1; steps <= 6; ++steps) {
    const auto s = h.meanStep(steps);
    ASSERT_TRUE(s.has_value());
    EXPECT_TRUE(s->matrix().isApprox(kStep.matrix(), 1e-9)) << "steps " << steps;
  }
  h.clear();
  EXPECT_EQ(h.size(), 0u);
}

TEST(MotionModel, OneDraggedFrameMovesTheMeanPredictionByAFraction) {
  // Four good frames, then one a person dragged 3 cm along the optical axis.
  Pose T;
  slam::MotionHistory h = steadyHistory(T);
  const Pose truth_next = kStep * kStep * T;
  Pose dragged = kStep * T;
  dragged.translation().z() += 0.03;
  h.push(dragged, kCapacity);
  const Pose last_only = *h.meanStep(1) * dragged;
  const Pose mean_of_four = *h.meanStep(4) * dragged;
  // The dragged frame itself is 3 cm off; the last step alone predicts the next frame 6 cm off,
  // the mean of four about 3.75.
  const double off_last = poseGap(last_only, truth_next).moved_m;
  const double off_mean = poseGap(mean_of_four, truth_next).moved_m;
  EXPECT_NEAR(off_last, 0.06, 0.005);
  EXPECT_NEAR(off_mean, 0.0375, 0.005);
}

TEST(MotionModel, TheLastStepStandsUnlessItIsAnOutlier) {
  const slam::PredictionTolerance tol{0.005, 1.0 * M_PI / 180.0};
  const auto run = [&](double drag_m) {
    Pose T;
    slam::MotionHistory h = steadyHistory(T);
    const Pose previous = T;
    T = kStep * T;
    T.translation().z() += drag_m;
    h.push(T, kCapacity);
    const Pose last_step = T * previous.inverse() * T;
    return std::make_pair(slam::robustPrediction(h, 4, last_step, T, tol), last_step);
  };
  // Constant velocity, and a step 1 cm off (7.5 mm from the mean's prediction, under 3 sigmas):
  // the last step's prediction, unchanged.
  for (double drag : {0.0, 0.01}) {
    const auto [p, last_step] = run(drag);
    EXPECT_TRUE(p.matrix() == last_step.matrix()) << "drag " << drag;
  }
  // A step 3 cm off: the mean's.
  const auto [p, last_step] = run(0.03);
  EXPECT_GT(poseGap(p, last_step).moved_m, 0.02);
}

// Camera centres 0.3 m apart and a 20 degree turn between the two orientations, whatever the
// poses' common world offset.
TEST(MotionModel, PoseGapIsTheCentreDistanceAndTheTurn) {
  const Pose world = makePose(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
                              Eigen::Vector3d(4, -1, 2));
  Pose a_wc = Pose::Identity(), b_wc = Pose::Identity();
  b_wc.linear() = Eigen::AngleAxisd(20.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  b_wc.translation() = Eigen::Vector3d(0.0, 0.3, 0.0);
  const PoseGap gap = poseGap((world * a_wc).inverse(), (world * b_wc).inverse());
  EXPECT_NEAR(gap.moved_m, 0.3, 1e-12);
  EXPECT_NEAR(gap.turned_rad * 180.0 / M_PI, 20.0, 1e-9);
  const PoseGap none = poseGap(world, world);
  EXPECT_NEAR(none.moved_m, 0.0, 1e-12);
  EXPECT_NEAR(none.turned_rad, 0.0, 1e-12);
}
