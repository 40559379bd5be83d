#include "yolo_slam/slam/odometry.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

using namespace yolo_slam;
using slam::ContinuousOdometry;

namespace {

Pose poseAt(double x, double yaw) {
  return makePose(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())), Eigen::Vector3d(x, 0, 0));
}

void expectNear(const Pose& a, const Pose& b, double tol = 1e-9) {
  EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), tol) << a.matrix() << "\nvs\n" << b.matrix();
}

}  // namespace

TEST(ContinuousOdometry, FollowsTrackedMotionWithIdentityMapToOdom) {
  ContinuousOdometry odo;
  for (int i = 0; i < 10; ++i) {
    const auto e = odo.update(i * 0.1, poseAt(0.05 * i, 0.01 * i), 0);
    expectNear(e.T_map_odom, Pose::Identity());
    expectNear(e.T_odom_base, poseAt(0.05 * i, 0.01 * i));
    EXPECT_FALSE(e.jumped);
    if (i > 0) {
      EXPECT_NEAR(e.linear.norm(), 0.5, 0.01);
      EXPECT_NEAR(e.angular.z(), 0.1, 1e-9);
    }
  }
}

TEST(ContinuousOdometry, LoopCorrectionGoesIntoMapToOdom) {
  ContinuousOdometry odo;
  odo.update(0.0, poseAt(0, 0), 0);
  const auto before = odo.update(0.1, poseAt(1.0, 0), 0);
  // A loop closure moves the SLAM pose by -0.3 m: odom must not jump.
  const auto at = odo.update(0.2, poseAt(0.7, 0), 1);
  EXPECT_TRUE(at.jumped);
  expectNear(at.T_odom_base, before.T_odom_base);
  expectNear(at.T_map_odom * at.T_odom_base, poseAt(0.7, 0));
  EXPECT_EQ(at.linear.norm(), 0.0);
  // After it, odom follows the motion again, map -> odom keeps the correction.
  const auto after = odo.update(0.3, poseAt(0.8, 0), 1);
  EXPECT_FALSE(after.jumped);
  expectNear(after.T_odom_base, poseAt(1.1, 0));
  expectNear(after.T_map_odom, at.T_map_odom);
}

TEST(ContinuousOdometry, LongGapIsNotBridged) {
  ContinuousOdometry odo(0.5);
  odo.update(0.0, poseAt(0, 0), 0);
  const auto e = odo.update(2.0, poseAt(3.0, 0.5), 0);
  EXPECT_TRUE(e.jumped);
  expectNear(e.T_odom_base, poseAt(0, 0));
  expectNear(e.T_map_odom * e.T_odom_base, poseAt(3.0, 0.5));
}

TEST(ContinuousOdometry, OutOfOrderStampHoldsStill) {
  ContinuousOdometry odo;
  odo.update(1.0, poseAt(0, 0), 0);
  const auto e = odo.update(0.9, poseAt(0.2, 0), 0);
  expectNear(e.T_odom_base, poseAt(0, 0));
  EXPECT_TRUE(e.jumped);
}
