// New map points from keyframe matches: ORB-SLAM2's checks, and the RGB-D free-space check that
// refuses a keypoint without depth triangulated in front of the surfaces the depth camera
// measured around it (a wrong match whose rays cross near the camera).
#include "yolo_slam/slam/triangulation.h"

#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/keyframe.h"

#include <gtest/gtest.h>

#include <memory>

using namespace yolo_slam;
using namespace yolo_slam::slam;

namespace {

constexpr double kWallDepth = 4.0;  // metres: the surface every measured keypoint lies on
constexpr double kBaseline = 0.2;   // metres between the two keyframes, along x
constexpr int kProbe = 0;           // index of the keypoint without depth in both keyframes

const CameraModel& camera() {
  static const CameraModel cam;
  return cam;
}

// Keypoint 0 at `probe_px` without depth; then a ring of keypoints around it, `ring_px` away,
// measured at `ring_depth` (none when ring_depth <= 0); then a row near the bottom of the image
// on the wall, so that the keyframe's near depth is the wall's.
KeyFramePtr makeKeyFrame(long id, double centre_x, const cv::Point2f& probe_px, double ring_depth,
                         float ring_px = 12.f) {
  const CameraModel& cam = camera();
  features::FeatureFrame ff;
  ff.stamp = static_cast<double>(id);
  ff.width = cam.width;
  ff.height = cam.height;
  auto add = [&](const cv::Point2f& px, double depth) {
    cv::KeyPoint kp(px, 31.f);
    kp.octave = 0;
    ff.keypoints.push_back(kp);
    ff.depth.push_back(depth > 0 ? static_cast<float>(depth) : -1.f);
    ff.right_u.push_back(depth > 0 ? static_cast<float>(px.x - cam.bf / depth) : -1.f);
    ff.dynamic.push_back(0);
  };
  add(probe_px, -1);
  const cv::Point2f ring[] = {{ring_px, 0}, {-ring_px, 0}, {0, ring_px}, {0, -ring_px}};
  for (const cv::Point2f& d : ring) add(probe_px + d, ring_depth);
  for (int k = 0; k < 40; ++k) add(cv::Point2f(40.f + 14.f * k, 440.f), kWallDepth);
  ff.keypoints_un = ff.keypoints;
  ff.descriptors = cv::Mat::zeros(static_cast<int>(ff.keypoints.size()), 32, CV_8U);
  auto pyr = std::make_shared<ScalePyramid>(ScalePyramid::make(8, 1.2));
  Frame f(ff, cam, FrameGeometry::make(cam), pyr, id);
  Pose T_cw = Pose::Identity();
  T_cw.translation() = Eigen::Vector3d(-centre_x, 0, 0);
  f.setPose(T_cw);
  return std::make_shared<KeyFrame>(id, f);
}

// Pixel of world point X in a camera at (centre_x, 0, 0) looking along +z.
cv::Point2f pixelOf(const Eigen::Vector3d& X, double centre_x) {
  const Eigen::Vector2d uv = camera().project(X - Eigen::Vector3d(centre_x, 0, 0));
  return {static_cast<float>(uv.x()), static_cast<float>(uv.y())};
}

// The probe of the first keyframe at the image centre, its match in the second keyframe where
// the point at `point_depth` on the probe's ray projects.
struct Pair {
  KeyFramePtr kf1, kf2;
};

Pair pairFor(double point_depth, double ring_depth, float ring_px = 12.f) {
  const cv::Point2f probe1(320.f, 240.f);
  const CameraModel& cam = camera();
  const Eigen::Vector3d X = cam.unproject(probe1.x, probe1.y, point_depth);
  return {makeKeyFrame(1, 0.0, probe1, ring_depth, ring_px),
          makeKeyFrame(2, kBaseline, pixelOf(X, kBaseline), ring_depth, ring_px)};
}

// Whether the pair's probes make a point with this free-space ratio.
bool made(const Pair& p, double ratio, Eigen::Vector3d* X_out = nullptr) {
  const TriangulationView v1(*p.kf1), v2(*p.kf2);
  Eigen::Vector3d X;
  const bool ok = triangulateMatch(camera(), v1, v2, kProbe, kProbe, ratio, X);
  if (X_out) *X_out = X;
  return ok;
}

}  // namespace

TEST(Triangulation, AKeypointWithoutDepthOnTheMeasuredWallMakesItsPoint) {
  Eigen::Vector3d X;
  ASSERT_TRUE(made(pairFor(kWallDepth, kWallDepth), 0.5, &X));
  EXPECT_NEAR(X.z(), kWallDepth, 1e-4);  // float pixels
}

TEST(Triangulation, RaysCrossingInFrontOfTheMeasuredWallAreRefused) {
  // A wrong match: the rays cross 1 m from the cameras, where the depth camera measured the wall
  // 4 m away all around the keypoint.
  const Pair p = pairFor(1.0, kWallDepth);
  EXPECT_FALSE(made(p, 0.5));
  EXPECT_TRUE(made(p, 0.0)) << "ratio 0 is ORB-SLAM2's behaviour: the point passes its checks";
}

TEST(Triangulation, WithoutMeasuredNeighboursTheKeyFramesNearDepthDecides) {
  // No depth anywhere near the keypoint (a region beyond the sensor's range): the keyframe's
  // near depth (the wall row, 4 m) is the bound.
  EXPECT_FALSE(made(pairFor(1.0, -1), 0.5));
  EXPECT_TRUE(made(pairFor(6.0, -1), 0.5));
  const TriangulationView v(*pairFor(1.0, -1).kf1);
  EXPECT_NEAR(v.near_depth, kWallDepth, 1e-6);
}

TEST(Triangulation, APointNearAMeasuredNearSurfaceIsKept) {
  // The keypoint sits on a near object measured at 1.2 m around it (its own pixel lost its
  // depth on an edge): a point at 1 m is not in measured free space.
  EXPECT_TRUE(made(pairFor(1.0, 1.2), 0.5));
}

TEST(Triangulation, OnlyKeypointsWithoutDepthAreJudged) {
  const Pair p = pairFor(1.0, kWallDepth);
  const TriangulationView v1(*p.kf1);
  EXPECT_FALSE(outsideMeasuredFreeSpace(v1, kProbe, 1.0, 0.5));
  EXPECT_TRUE(outsideMeasuredFreeSpace(v1, kProbe, 2.5, 0.5));
  EXPECT_TRUE(outsideMeasuredFreeSpace(v1, 1, 0.1, 0.5)) << "keypoint 1 has depth";
  EXPECT_TRUE(outsideMeasuredFreeSpace(v1, kProbe, 0.1, 0.0)) << "ratio 0: off";
}

TEST(Triangulation, NeighboursBeyondTheRadiusDoNotCount) {
  // A ring measured at 8 m: counted, it puts the bound at 4 m and refuses a point at 3 m; 40 px
  // away it is not counted, the keyframe's near depth (the 4 m wall) puts the bound at 2 m.
  EXPECT_FALSE(made(pairFor(3.0, 8.0, 12.f), 0.5));
  EXPECT_TRUE(made(pairFor(3.0, 8.0, 40.f), 0.5));
}
