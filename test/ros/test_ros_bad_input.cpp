// Bad input per nodelet (wrong encoding, empty image, missing camera_info, inconsistent
// keypoint frame): each nodelet logs a clear ROS error naming the problem and keeps running,
// which the test proves by feeding good frames afterwards and receiving boxes, keypoint frames
// and a pose.
#include <gtest/gtest.h>
#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>
#include <opencv2/imgproc.hpp>

#include <atomic>
#include <functional>

#include "rosout_watch.h"
#include "test_frames.h"
#include "yolo_slam/BoundingBoxes.h"
#include "yolo_slam/KeypointFrame.h"

namespace enc = sensor_msgs::image_encodings;
using rosgraph_msgs::Log;

namespace {

class BadInput : public ::testing::Test {
 protected:
  // The nodelets share one manager process: a topic counts one connection for all of them, so
  // readiness is checked per nodelet (its own output topic or service).
  static void SetUpTestSuite() {
    nh_ = new ros::NodeHandle;
    watch_ = new RosoutWatch(*nh_);
    rgb_pub_ = nh_->advertise<sensor_msgs::Image>("/camera/rgb/image_raw", 10);
    depth_pub_ = nh_->advertise<sensor_msgs::Image>("/camera/depth_registered/image_raw", 10);
    info_pub_ = nh_->advertise<sensor_msgs::CameraInfo>("/camera/rgb/camera_info", 1, true);
    kf_pub_ = nh_->advertise<yolo_slam::KeypointFrame>("/yolo_slam/keypoint_frame", 10);
    boxes_sub_ = nh_->subscribe<yolo_slam::BoundingBoxes>(
        "/yolo_slam/boxes", 100, +[](const yolo_slam::BoundingBoxes::ConstPtr&) { ++boxes_; });
    kf_sub_ = nh_->subscribe<yolo_slam::KeypointFrame>(
        "/yolo_slam/keypoint_frame", 100, +[](const yolo_slam::KeypointFrame::ConstPtr& m) {
          if (m->header.frame_id != "test") ++frames_;
        });
    pose_sub_ = nh_->subscribe<geometry_msgs::PoseStamped>(
        "/yolo_slam/pose", 100, +[](const geometry_msgs::PoseStamped::ConstPtr&) { ++poses_; });
    // A textured scene (blurred noise) with a flat wall at 2 m: plenty of ORB corners.
    rgb_ = cv::Mat(480, 640, CV_8UC3);
    cv::randu(rgb_, 0, 255);
    cv::GaussianBlur(rgb_, rgb_, cv::Size(5, 5), 1.5);
    depth_ = cv::Mat(480, 640, CV_32F, cv::Scalar(2.0f));
    // Wait until the nodelets are connected.
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(30.0);
    while (ros::WallTime::now() < end &&
           (rgb_pub_.getNumSubscribers() < 1 || depth_pub_.getNumSubscribers() < 1 ||
            kf_pub_.getNumSubscribers() < 2 || boxes_sub_.getNumPublishers() < 1 ||
            !ros::service::exists("/yolo_slam/save_trajectory", false)))
      ros::WallDuration(0.1).sleep();
    ros::WallDuration(1.0).sleep();
  }

  // Sends `bad`, then good frames at 5 Hz (they flush the approximate-time synchroniser)
  // until `ok()` or the timeout.
  static bool sendUntil(const std::function<void(const ros::Time&)>& bad,
                        const std::function<bool()>& ok, double timeout_s) {
    t_ += 1.0;
    bad(ros::Time(t_));
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (ros::WallTime::now() < end) {
      if (ok()) return true;
      t_ += 0.2;
      rgb_pub_.publish(toImage(rgb_, enc::BGR8, ros::Time(t_)));
      depth_pub_.publish(toImage(depth_, enc::TYPE_32FC1, ros::Time(t_)));
      ros::WallDuration(0.2).sleep();
    }
    return ok();
  }

  static bool logged(const std::string& needle) {
    return watch_->count(Log::ERROR, needle) > 0;
  }

  static ros::NodeHandle* nh_;
  static RosoutWatch* watch_;
  static ros::Publisher rgb_pub_, depth_pub_, info_pub_, kf_pub_;
  static ros::Subscriber boxes_sub_, kf_sub_, pose_sub_;
  static std::atomic<int> boxes_, frames_, poses_;
  static cv::Mat rgb_, depth_;
  static double t_;
};

ros::NodeHandle* BadInput::nh_;
RosoutWatch* BadInput::watch_;
ros::Publisher BadInput::rgb_pub_, BadInput::depth_pub_, BadInput::info_pub_, BadInput::kf_pub_;
ros::Subscriber BadInput::boxes_sub_, BadInput::kf_sub_, BadInput::pose_sub_;
std::atomic<int> BadInput::boxes_{0}, BadInput::frames_{0}, BadInput::poses_{0};
cv::Mat BadInput::rgb_, BadInput::depth_;
double BadInput::t_ = 1000.0;

TEST_F(BadInput, DetectorRejectsWrongEncodingAndEmptyImages) {
  EXPECT_TRUE(sendUntil([](const ros::Time& t) { rgb_pub_.publish(toImage(depth_, enc::TYPE_32FC1, t)); },
                        [] { return logged("Detector: image rejected: unsupported colour encoding '32FC1'"); }, 15))
      << watch_->dump();
  EXPECT_TRUE(sendUntil([](const ros::Time& t) { rgb_pub_.publish(toImage(cv::Mat(0, 0, CV_8UC3), enc::RGB8, t)); },
                        [] { return logged("Detector: image rejected: empty image"); }, 15))
      << watch_->dump();
  // Still running: boxes for the good frames.
  const int before = boxes_;
  EXPECT_TRUE(sendUntil([](const ros::Time&) {}, [&] { return boxes_ > before + 2; }, 15));
}

TEST_F(BadInput, MissingCameraInfoIsReportedByScreeningAndSlam) {
  EXPECT_TRUE(sendUntil([](const ros::Time&) {},
                        [] { return logged("Screening: frame") && logged("no camera_info received on /camera/rgb/camera_info"); }, 20))
      << watch_->dump();
  EXPECT_EQ(frames_, 0);
  // Frames within CameraSource's 1 s grace of the first one are skipped quietly (camera_info and
  // images race at start-up); the later ones are rejected with the error.
  EXPECT_TRUE(sendUntil(
      [](const ros::Time& t) {
        for (double dt : {0.0, 0.6, 1.2, 1.8}) {
          yolo_slam::KeypointFrame kf;
          kf.header.stamp = t + ros::Duration(dt);
          kf.header.frame_id = "test";
          kf.width = 640;
          kf.height = 480;
          kf_pub_.publish(kf);
        }
        t_ += 2.0;
      },
      [] { return logged("Slam: frame") && logged("no camera_info received"); }, 15))
      << watch_->dump();
}

TEST_F(BadInput, ScreeningRejectsWrongDepthEncodingAndEmptyDepth) {
  const sensor_msgs::CameraInfo info = tum3CameraInfo();
  info_pub_.publish(info);
  ros::WallDuration(0.5).sleep();
  EXPECT_TRUE(sendUntil(
      [](const ros::Time& t) {
        rgb_pub_.publish(toImage(rgb_, enc::BGR8, t));
        depth_pub_.publish(toImage(rgb_, enc::RGB8, t));
      },
      [] { return logged("unsupported depth encoding 'rgb8' on /camera/depth_registered/image_raw"); }, 15))
      << watch_->dump();
  EXPECT_TRUE(sendUntil(
      [](const ros::Time& t) {
        rgb_pub_.publish(toImage(rgb_, enc::BGR8, t));
        depth_pub_.publish(toImage(cv::Mat(0, 0, CV_32F), enc::TYPE_32FC1, t));
      },
      [] { return logged("empty image on /camera/depth_registered/image_raw"); }, 15))
      << watch_->dump();
  // Unregistered depth (the depth camera's own frame) is refused, not screened pixel for pixel.
  EXPECT_TRUE(sendUntil(
      [](const ros::Time& t) {
        rgb_pub_.publish(toImage(rgb_, enc::BGR8, t));
        auto d = toImage(depth_, enc::TYPE_32FC1, t);
        d->header.frame_id = "camera_depth_optical_frame";
        depth_pub_.publish(d);
      },
      [] { return logged("depth is not registered to colour"); }, 15))
      << watch_->dump();
}

TEST_F(BadInput, SlamRejectsInconsistentKeypointFrames) {
  EXPECT_TRUE(sendUntil(
      [](const ros::Time& t) {
        yolo_slam::KeypointFrame kf;
        kf.header.stamp = t;
        kf.header.frame_id = "test";
        kf.width = 640;
        kf.height = 480;
        kf.keypoints.resize(10);
        kf.descriptors.resize(320);
        kf.depth.resize(9);  // one short
        kf.dynamic.resize(10);
        kf_pub_.publish(kf);
      },
      [] { return logged("Slam: frame") && logged("inconsistent arrays"); }, 15))
      << watch_->dump();
}

TEST_F(BadInput, GraphStillRunsAfterwards) {
  EXPECT_TRUE(sendUntil([](const ros::Time&) {}, [] { return frames_ >= 3 && poses_ >= 1; }, 30))
      << "keypoint frames " << frames_ << ", poses " << poses_ << "\n" << watch_->dump();
  EXPECT_EQ(watch_->count(Log::FATAL, ""), 0u);
}

// The core library's own warnings (here: tracking's motion-model reset on a stamp gap) reach
// /rosout through the log sink the nodelets install, not the manager's stderr.
TEST_F(BadInput, CoreWarningsReachRosout) {
  constexpr double kGapS = 5.0;  // above Tracking.maxStampGap (1 s)
  ASSERT_TRUE(sendUntil([](const ros::Time&) {}, [] { return poses_ >= 3; }, 30)) << watch_->dump();
  EXPECT_TRUE(sendUntil([](const ros::Time&) { t_ += kGapS; },
                        [] { return watch_->count(Log::WARN, "timestamp jump of") > 0; }, 20))
      << watch_->dump();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_ros_bad_input");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
