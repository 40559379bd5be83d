// Round trips between the yolo_slam messages and the core types, and the checks on bad images.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/image_encodings.h>

#include <cstring>

#include "yolo_slam/common/error.h"
#include "yolo_slam/ros/conversions.h"
#include "../../src/ros/nodelet_common.h"

using namespace yolo_slam;
namespace enc = sensor_msgs::image_encodings;

static sensor_msgs::Image makeImage(int w, int h, const std::string& e, int bytes_per_pixel) {
  sensor_msgs::Image m;
  m.width = w;
  m.height = h;
  m.encoding = e;
  m.step = w * bytes_per_pixel;
  m.data.resize(static_cast<size_t>(m.step) * h);
  for (size_t i = 0; i < m.data.size(); ++i) m.data[i] = static_cast<uint8_t>(i * 7 + 3);
  return m;
}

TEST(Conversions, BoxRoundTrip) {
  detection::Box b;
  b.class_id = 14;
  b.label = "person";
  b.score = 0.8f;
  b.rect = cv::Rect2f(10.5f, 20.f, 30.f, 100.25f);
  detection::Boxes boxes{b, b};
  boxes[1].label = "dog";
  BoundingBoxes msg;
  ros1::toMsg(boxes, msg);
  ASSERT_EQ(msg.boxes.size(), 2u);
  const detection::Boxes back = ros1::boxesFromMsg(msg.boxes);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].class_id, 14);
  EXPECT_EQ(back[0].label, "person");
  EXPECT_EQ(back[1].label, "dog");
  EXPECT_FLOAT_EQ(back[0].score, 0.8f);
  EXPECT_EQ(back[0].rect, b.rect);
}

static features::FeatureFrame makeFrame(size_t n) {
  features::FeatureFrame f;
  f.width = 640;
  f.height = 480;
  f.stamp = 12.5;
  f.descriptors = cv::Mat(static_cast<int>(n), 32, CV_8U);
  for (size_t i = 0; i < n; ++i) {
    cv::KeyPoint k(cv::Point2f(10.f + i, 20.f + 0.5f * i), 31.f, 45.f + i, 10.f + i,
                   static_cast<int>(i % 8));
    f.keypoints.push_back(k);
    f.depth.push_back(i % 3 == 0 ? 0.f : 1.0f + 0.1f * i);
    f.dynamic.push_back(i % 4 == 0 ? 1 : 0);
    f.motion.push_back(static_cast<int8_t>(static_cast<int>(i % 3) - 1));
    f.boxed.push_back(i % 5 == 1 ? 1 : 0);
    for (int j = 0; j < 32; ++j) f.descriptors.at<uint8_t>(static_cast<int>(i), j) = static_cast<uint8_t>(i * 32 + j);
  }
  f.keypoints_un = f.keypoints;
  return f;
}

TEST(Conversions, KeypointFrameRoundTrip) {
  const features::FeatureFrame f = makeFrame(50);
  detection::Box b;
  b.label = "person";
  b.rect = cv::Rect2f(1, 2, 3, 4);
  KeypointFrame msg;
  msg.header.stamp = ros::Time(12.5);
  ros1::toMsg(f, {b}, msg);
  EXPECT_EQ(msg.keypoints.size(), 50u);
  EXPECT_EQ(msg.motion.size(), 50u);
  EXPECT_EQ(msg.descriptors.size(), 50u * 32);
  EXPECT_EQ(msg.boxes.size(), 1u);
  CameraModel cam;  // no distortion
  const features::FeatureFrame g = ros1::fromMsg(msg, cam);
  ASSERT_EQ(g.motion.size(), 50u);
  ASSERT_EQ(g.boxed.size(), 50u);
  EXPECT_DOUBLE_EQ(g.stamp, 12.5);
  EXPECT_EQ(g.width, 640);
  ASSERT_EQ(g.size(), 50u);
  for (size_t i = 0; i < 50; ++i) {
    EXPECT_EQ(g.keypoints[i].pt, f.keypoints[i].pt);
    EXPECT_EQ(g.keypoints[i].octave, f.keypoints[i].octave);
    EXPECT_FLOAT_EQ(g.keypoints[i].angle, f.keypoints[i].angle);
    EXPECT_FLOAT_EQ(g.keypoints[i].response, f.keypoints[i].response);
    EXPECT_EQ(g.keypoints_un[i].pt, f.keypoints[i].pt);
    EXPECT_EQ(g.depth[i], f.depth[i]);
    EXPECT_EQ(g.dynamic[i], f.dynamic[i]);
    EXPECT_EQ(g.motion[i], f.motion[i]);
    EXPECT_EQ(g.boxed[i], f.boxed[i]);
    if (f.depth[i] > 0)
      EXPECT_NEAR(g.right_u[i], f.keypoints[i].pt.x - cam.bf / f.depth[i], 1e-4);
    else
      EXPECT_LT(g.right_u[i], 0.f);
  }
  EXPECT_EQ(cv::norm(g.descriptors, f.descriptors, cv::NORM_HAMMING), 0);
}

TEST(Conversions, KeypointFrameUndistortsWithTheCamera) {
  KeypointFrame msg;
  ros1::toMsg(makeFrame(10), {}, msg);
  CameraModel cam;
  cam.k1 = -0.2;
  cam.k2 = 0.05;
  const features::FeatureFrame g = ros1::fromMsg(msg, cam);
  const std::vector<cv::Point2f> un = cam.undistort({g.keypoints[5].pt});
  EXPECT_NEAR(g.keypoints_un[5].pt.x, un[0].x, 1e-4);
  EXPECT_NEAR(g.keypoints_un[5].pt.y, un[0].y, 1e-4);
  EXPECT_GT(cv::norm(g.keypoints_un[5].pt - g.keypoints[5].pt), 0.1);
}

TEST(Conversions, KeypointFrameRejectsInconsistentArrays) {
  KeypointFrame msg;
  ros1::toMsg(makeFrame(10), {}, msg);
  msg.depth.pop_back();
  EXPECT_THROW(ros1::fromMsg(msg, CameraModel()), Error);
  ros1::toMsg(makeFrame(10), {}, msg);
  msg.descriptors.resize(10 * 31);
  EXPECT_THROW(ros1::fromMsg(msg, CameraModel()), Error);
  ros1::toMsg(makeFrame(10), {}, msg);
  msg.width = 0;
  EXPECT_THROW(ros1::fromMsg(msg, CameraModel()), Error);
}

TEST(Conversions, ColourImages) {
  sensor_msgs::Image rgb = makeImage(4, 3, enc::RGB8, 3);
  cv::Mat bgr = ros1::imageToBgr(rgb, "t");
  ASSERT_EQ(bgr.type(), CV_8UC3);
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 2)[0], rgb.data[1 * 12 + 2 * 3 + 2]);  // B from R G B
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 2)[2], rgb.data[1 * 12 + 2 * 3 + 0]);
  bool is_rgb = false;
  cv::Mat view = ros1::imageView(rgb, "t", is_rgb);
  EXPECT_TRUE(is_rgb);
  EXPECT_EQ(view.data, rgb.data.data());  // no copy
  sensor_msgs::Image mono = makeImage(4, 3, enc::MONO8, 1);
  EXPECT_EQ(ros1::imageToBgr(mono, "t").at<cv::Vec3b>(2, 3)[1], mono.data[2 * 4 + 3]);
  // Padded rows are honoured.
  sensor_msgs::Image padded = makeImage(4, 3, enc::BGR8, 3);
  padded.step = 16;
  padded.data.resize(16 * 3);
  EXPECT_EQ(ros1::imageToBgr(padded, "t").at<cv::Vec3b>(2, 1)[0], padded.data[2 * 16 + 3]);
}

TEST(Conversions, BadColourImagesThrowNamingTheTopic) {
  sensor_msgs::Image depth = makeImage(4, 3, enc::TYPE_32FC1, 4);
  try {
    ros1::imageToBgr(depth, "/camera/rgb/image_color");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/camera/rgb/image_color"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("32FC1"), std::string::npos);
  }
  sensor_msgs::Image empty;
  empty.encoding = enc::RGB8;
  EXPECT_THROW(ros1::imageToBgr(empty, "t"), Error);
  sensor_msgs::Image truncated = makeImage(4, 3, enc::RGB8, 3);
  truncated.data.resize(20);
  EXPECT_THROW(ros1::imageToBgr(truncated, "t"), Error);
}

TEST(Conversions, DepthImagesFollowRep118) {
  sensor_msgs::Image mm = makeImage(2, 2, enc::TYPE_16UC1, 2);
  const uint16_t v[4] = {1500, 0, 65535, 250};
  std::memcpy(mm.data.data(), v, 8);
  cv::Mat m = ros1::depthToMetres(mm, "t");
  ASSERT_EQ(m.type(), CV_32F);
  EXPECT_FLOAT_EQ(m.at<float>(0, 0), 1.5f);
  EXPECT_FLOAT_EQ(m.at<float>(0, 1), 0.f);
  EXPECT_FLOAT_EQ(m.at<float>(1, 1), 0.25f);
  sensor_msgs::Image f = makeImage(2, 2, enc::TYPE_32FC1, 4);
  const float fv[4] = {2.0f, std::numeric_limits<float>::quiet_NaN(), -1.f, 0.5f};
  std::memcpy(f.data.data(), fv, 16);
  m = ros1::depthToMetres(f, "t");
  EXPECT_FLOAT_EQ(m.at<float>(0, 0), 2.0f);
  EXPECT_FLOAT_EQ(m.at<float>(0, 1), 0.f);
  EXPECT_FLOAT_EQ(m.at<float>(1, 0), 0.f);
  EXPECT_FLOAT_EQ(m.at<float>(1, 1), 0.5f);
  EXPECT_THROW(ros1::depthToMetres(makeImage(2, 2, enc::RGB8, 3), "t"), Error);
  sensor_msgs::Image empty;
  empty.encoding = enc::TYPE_32FC1;
  EXPECT_THROW(ros1::depthToMetres(empty, "t"), Error);
}

TEST(Conversions, CameraInfo) {
  sensor_msgs::CameraInfo info;
  info.width = 320;
  info.height = 240;
  info.K = {300, 0, 160, 0, 310, 120, 0, 0, 1};
  info.distortion_model = "plumb_bob";
  info.D = {0.1, -0.2, 0.001, 0.002, 0.05};
  CameraModel base;  // bf 40, fx 535.4
  const CameraModel cam = ros1::cameraFromInfo(info, base, "t");
  EXPECT_EQ(cam.width, 320);
  EXPECT_DOUBLE_EQ(cam.fx, 300);
  EXPECT_DOUBLE_EQ(cam.fy, 310);
  EXPECT_DOUBLE_EQ(cam.cy, 120);
  EXPECT_DOUBLE_EQ(cam.k3, 0.05);
  EXPECT_NEAR(cam.baseline(), base.baseline(), 1e-12);
  info.K[0] = 0;
  EXPECT_THROW(ros1::cameraFromInfo(info, base, "t"), Error);
}

// Rectified images (image_proc's image_rect) are already undistorted: the projection matrix P
// holds their intrinsics, and D must not be applied a second time.
TEST(Conversions, CameraInfoRectifiedUsesP) {
  sensor_msgs::CameraInfo info;
  info.width = 320;
  info.height = 240;
  info.K = {300, 0, 160, 0, 310, 120, 0, 0, 1};
  info.P = {290, 0, 158, 0, 0, 295, 118, 0, 0, 0, 1, 0};
  info.distortion_model = "plumb_bob";
  info.D = {0.1, -0.2, 0.001, 0.002, 0.05};
  CameraModel base;
  const CameraModel raw = ros1::cameraFromInfo(info, base, "t", false);
  EXPECT_DOUBLE_EQ(raw.fx, 300);
  EXPECT_DOUBLE_EQ(raw.cx, 160);
  EXPECT_TRUE(raw.hasDistortion());
  const CameraModel rect = ros1::cameraFromInfo(info, base, "t", true);
  EXPECT_DOUBLE_EQ(rect.fx, 290);
  EXPECT_DOUBLE_EQ(rect.fy, 295);
  EXPECT_DOUBLE_EQ(rect.cx, 158);
  EXPECT_DOUBLE_EQ(rect.cy, 118);
  EXPECT_FALSE(rect.hasDistortion());
  EXPECT_EQ(rect.width, 320);
  EXPECT_NEAR(rect.baseline(), base.baseline(), 1e-12);
  info.P.fill(0);
  EXPECT_THROW(ros1::cameraFromInfo(info, base, "t", true), Error);
  EXPECT_NO_THROW(ros1::cameraFromInfo(info, base, "t", false));
}

TEST(Conversions, RectifiedParameter) {
  using ros1::Rectified;
  EXPECT_TRUE(ros1::isRectified(ros1::parseRectified("auto"), "/camera/rgb/image_rect_color"));
  EXPECT_FALSE(ros1::isRectified(ros1::parseRectified("auto"), "/camera/rgb/image_raw"));
  EXPECT_TRUE(ros1::isRectified(ros1::parseRectified("true"), "/camera/rgb/image_raw"));
  EXPECT_FALSE(ros1::isRectified(ros1::parseRectified("false"), "/camera/rgb/image_rect"));
  EXPECT_THROW(ros1::parseRectified("yes"), Error);
}

// Frames before the first camera_info are skipped quietly for 1 s of stamps (start-up race of
// the subscriptions), then reported; never once camera_info came, never without camera_info.
TEST(CameraSource, FramesJustBeforeTheFirstCameraInfoAreAwaited) {
  sensor_msgs::CameraInfo info;
  info.width = 320;
  info.height = 240;
  info.K = {300, 0, 160, 0, 310, 120, 0, 0, 1};
  ros1::CameraSource source;
  source.configure(CameraModel(), true);
  const ros::Time t0(100.0);
  EXPECT_TRUE(source.awaitingFirstInfo(t0));
  EXPECT_TRUE(source.awaitingFirstInfo(t0 + ros::Duration(0.9)));
  EXPECT_FALSE(source.awaitingFirstInfo(t0 + ros::Duration(1.1)));
  EXPECT_THROW(source.get("t"), Error);
  source.update(info, "t");
  EXPECT_FALSE(source.awaitingFirstInfo(t0 + ros::Duration(0.1)));
  EXPECT_EQ(source.get("t").width, 320);
  ros1::CameraSource from_settings;
  from_settings.configure(CameraModel(), false);
  EXPECT_FALSE(from_settings.awaitingFirstInfo(t0));
}

TEST(Conversions, Poses) {
  const Pose T = makePose(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
                          Eigen::Vector3d(1, -2, 3));
  EXPECT_TRUE(ros1::poseFromMsg(ros1::poseToMsg(T)).isApprox(T, 1e-12));
  EXPECT_TRUE(ros1::transformFromMsg(ros1::transformToMsg(T)).isApprox(T, 1e-12));
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_ros_conversions");
  return RUN_ALL_TESTS();
}
