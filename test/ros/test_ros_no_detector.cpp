// A Detector that never answers does not stop the graph: the Screening nodelet holds frames back
// only for the first seconds of stamps (so no map starts on people before any detection), then
// publishes them without boxes and warns.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>
#include <opencv2/imgproc.hpp>

#include <atomic>
#include <cstdio>
#include <mutex>
#include <vector>

#include "rosout_watch.h"
#include "test_frames.h"
#include "yolo_slam/KeypointFrame.h"

namespace enc = sensor_msgs::image_encodings;
using rosgraph_msgs::Log;

namespace {

constexpr double kFrameRateHz = 30.0;
constexpr int kFrames = 150;             // 5 s of stamps
constexpr double kHoldBackS = 2.0;       // the Screening nodelet's longest wait for boxes
constexpr double kStampSlackS = 0.1;     // a few frames of scheduling either side

std::mutex g_mutex;  // guards g_stamps (subscriber thread vs test thread)
std::vector<double> g_stamps;

TEST(NoDetector, FramesFlowWithoutBoxesAfterTheHoldBack) {
  ros::NodeHandle nh;
  RosoutWatch watch(nh);
  ros::Publisher rgb_pub = nh.advertise<sensor_msgs::Image>("/camera/rgb/image_raw", 10);
  ros::Publisher depth_pub = nh.advertise<sensor_msgs::Image>("/camera/depth_registered/image_raw", 10);
  ros::Publisher info_pub = nh.advertise<sensor_msgs::CameraInfo>("/camera/rgb/camera_info", 1, true);
  ros::Subscriber kf_sub = nh.subscribe<yolo_slam::KeypointFrame>(
      "/yolo_slam/keypoint_frame", 500, +[](const yolo_slam::KeypointFrame::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(g_mutex);
        g_stamps.push_back(m->header.stamp.toSec());
      });
  const sensor_msgs::CameraInfo info = tum3CameraInfo();
  info_pub.publish(info);
  const ros::WallTime ready = ros::WallTime::now() + ros::WallDuration(30.0);
  while (ros::WallTime::now() < ready && (rgb_pub.getNumSubscribers() < 1 || depth_pub.getNumSubscribers() < 1 ||
                                          kf_sub.getNumPublishers() < 1))
    ros::WallDuration(0.1).sleep();
  ros::WallDuration(1.0).sleep();

  cv::Mat rgb(480, 640, CV_8UC3);
  cv::randu(rgb, 0, 255);
  cv::GaussianBlur(rgb, rgb, cv::Size(5, 5), 1.5);
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.0f));
  const double t0 = 2000.0;
  for (int i = 0; i < kFrames; ++i) {
    const ros::Time t(t0 + i / kFrameRateHz);
    rgb_pub.publish(toImage(rgb, enc::BGR8, t));
    depth_pub.publish(toImage(depth, enc::TYPE_32FC1, t));
    ros::WallDuration(1.0 / kFrameRateHz).sleep();
  }
  ros::WallDuration(2.0).sleep();

  std::lock_guard<std::mutex> lock(g_mutex);
  ASSERT_FALSE(g_stamps.empty()) << "no keypoint frame at all: the graph stopped\n" << watch.dump();
  std::printf("[no_detector] %zu of %d frames published, the first %.3f s after the first frame\n", g_stamps.size(),
              kFrames, g_stamps.front() - t0);
  EXPECT_GE(g_stamps.front() - t0, kHoldBackS - kStampSlackS) << "frames were published before the hold-back ended";
  EXPECT_LE(g_stamps.front() - t0, kHoldBackS + kStampSlackS);
  // After the hold-back every frame goes through (the synchroniser keeps the last one).
  const int expected = kFrames - static_cast<int>(kHoldBackS * kFrameRateHz);
  EXPECT_GE(static_cast<int>(g_stamps.size()), expected - 10);
  EXPECT_GT(watch.count(Log::WARN, "no boxes on"), 0u) << watch.dump();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_ros_no_detector");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
