#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/features/frame_builder.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <limits>

using namespace yolo_slam;
using namespace yolo_slam::features;

namespace {

cv::Mat loadTumBgr() {
  const std::string path = joinPath(
      sharedDir(), "data/tum/rgbd_dataset_freiburg3_walking_xyz/rgb/1341846316.570121.png");
  cv::Mat img = cv::imread(path, cv::IMREAD_COLOR);
  if (img.empty()) throw Error(path + ": missing; set YOLO_SLAM_SHARED to the shared folder");
  return img;
}

// Depth that varies per pixel so that reading the wrong pixel is detected; a band of invalid
// values (0, NaN, negative) on the left.
cv::Mat makeDepth(int w, int h) {
  cv::Mat d(h, w, CV_32F);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      float val = 1.0f + 0.001f * u + 0.0001f * v;
      if (u < 160) val = (u % 3 == 0) ? 0.0f : (u % 3 == 1 ? std::numeric_limits<float>::quiet_NaN() : -1.0f);
      d.at<float>(v, u) = val;
    }
  }
  return d;
}

}  // namespace

TEST(CameraModel, ProjectUnprojectRoundTrip) {
  CameraModel cam;
  for (double u : {0.0, 100.5, 320.1, 639.0}) {
    for (double v : {0.0, 247.6, 479.0}) {
      for (double z : {0.3, 1.7, 8.0}) {
        Eigen::Vector3d p = cam.unproject(u, v, z);
        EXPECT_NEAR(p.z(), z, 1e-12);
        Eigen::Vector2d uv = cam.project(p);
        EXPECT_NEAR(uv.x(), u, 1e-9);
        EXPECT_NEAR(uv.y(), v, 1e-9);
      }
    }
  }
}

TEST(FrameBuilder, DepthAndVirtualRightCoordinate) {
  cv::Mat bgr = loadTumBgr();
  OrbExtractor orb(OrbOptions{});
  CameraModel cam;
  cv::Mat depth = makeDepth(bgr.cols, bgr.rows);
  FeatureFrame f = buildFeatureFrame(orb, cam, bgr, depth, 12.5);
  EXPECT_DOUBLE_EQ(f.stamp, 12.5);
  EXPECT_EQ(f.width, 640);
  EXPECT_EQ(f.height, 480);
  ASSERT_GT(f.size(), 900u);
  ASSERT_EQ(f.keypoints_un.size(), f.size());
  ASSERT_EQ(f.depth.size(), f.size());
  ASSERT_EQ(f.right_u.size(), f.size());
  ASSERT_EQ(f.dynamic.size(), f.size());
  EXPECT_EQ(f.descriptors.rows, static_cast<int>(f.size()));
  EXPECT_EQ(f.countDynamic(), 0u);
  int valid = 0, invalid = 0;
  for (size_t i = 0; i < f.size(); ++i) {
    const cv::KeyPoint& kp = f.keypoints[i];
    EXPECT_EQ(kp.pt, f.keypoints_un[i].pt);  // no distortion
    const int u = cvRound(kp.pt.x), v = cvRound(kp.pt.y);
    if (u < 160) {
      EXPECT_LE(f.depth[i], 0.0f);
      EXPECT_LT(f.right_u[i], 0.0f);
      ++invalid;
    } else {
      const float d = 1.0f + 0.001f * u + 0.0001f * v;
      EXPECT_FLOAT_EQ(f.depth[i], d);
      EXPECT_NEAR(f.right_u[i], kp.pt.x - cam.bf / d, 1e-3);
      ++valid;
    }
  }
  EXPECT_GT(valid, 100);
  EXPECT_GT(invalid, 50);

  // No depth image at all: every keypoint without depth.
  FeatureFrame g = buildFeatureFrame(orb, cam, bgr, cv::Mat(), 0.0);
  ASSERT_EQ(g.size(), f.size());
  for (size_t i = 0; i < g.size(); ++i) EXPECT_LE(g.depth[i], 0.0f);
}

TEST(FrameBuilder, HonoursChannelOrderAndRejectsBadDepth) {
  cv::Mat bgr = loadTumBgr();
  cv::Mat gray_bgr, gray_rgb;
  cv::cvtColor(bgr, gray_bgr, cv::COLOR_BGR2GRAY);
  cv::cvtColor(bgr, gray_rgb, cv::COLOR_RGB2GRAY);
  EXPECT_EQ(cv::norm(toGray(bgr, false), gray_bgr, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(toGray(bgr, true), gray_rgb, cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(gray_bgr, gray_rgb, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(toGray(gray_bgr, true), gray_bgr, cv::NORM_L1), 0.0);

  OrbExtractor orb(OrbOptions{});
  CameraModel cam;
  cam.rgb_order = false;
  FeatureFrame a = buildFeatureFrame(orb, cam, bgr, cv::Mat(), 0.0);
  FeatureFrame b = buildFeatureFrame(orb, cam, gray_bgr, cv::Mat(), 0.0);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_L1), 0.0);

  EXPECT_THROW(buildFeatureFrame(orb, cam, bgr, cv::Mat(480, 640, CV_16U, cv::Scalar(0)), 0.0), Error);
  EXPECT_THROW(buildFeatureFrame(orb, cam, bgr, cv::Mat(240, 320, CV_32F, cv::Scalar(0)), 0.0), Error);
  EXPECT_THROW(buildFeatureFrame(orb, cam, cv::Mat(), cv::Mat(), 0.0), Error);
  EXPECT_THROW(buildFeatureFrame(orb, cam, cv::Mat(480, 640, CV_16UC3), cv::Mat(), 0.0), Error);
}

TEST(FrameBuilder, UndistortsKeypointsButReadsDepthAtRawPixel) {
  cv::Mat bgr = loadTumBgr();
  OrbExtractor orb(OrbOptions{});
  CameraModel cam;
  cam.k1 = 0.2;
  cam.k2 = -0.5;
  cam.p1 = 0.001;
  cv::Mat depth = makeDepth(bgr.cols, bgr.rows);
  FeatureFrame f = buildFeatureFrame(orb, cam, bgr, depth, 0.0);
  ASSERT_GT(f.size(), 0u);
  std::vector<cv::Point2f> raw;
  for (const auto& kp : f.keypoints) raw.push_back(kp.pt);
  std::vector<cv::Point2f> un = cam.undistort(raw);
  int moved = 0;
  for (size_t i = 0; i < f.size(); ++i) {
    EXPECT_NEAR(f.keypoints_un[i].pt.x, un[i].x, 1e-4);
    EXPECT_NEAR(f.keypoints_un[i].pt.y, un[i].y, 1e-4);
    EXPECT_EQ(f.keypoints_un[i].octave, f.keypoints[i].octave);
    moved += cv::norm(f.keypoints_un[i].pt - f.keypoints[i].pt) > 1.0 ? 1 : 0;
    const int u = cvRound(f.keypoints[i].pt.x), v = cvRound(f.keypoints[i].pt.y);
    if (u >= 160) {
      const float d = 1.0f + 0.001f * u + 0.0001f * v;
      EXPECT_FLOAT_EQ(f.depth[i], d);
      EXPECT_NEAR(f.right_u[i], f.keypoints_un[i].pt.x - cam.bf / d, 1e-3);
    }
  }
  EXPECT_GT(moved, static_cast<int>(f.size()) / 2);
}
