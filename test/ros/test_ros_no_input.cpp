// A graph whose image topics stay silent says so: the Screening nodelet names each topic it has
// not heard from (and how many publishers it has) until both images have arrived once, then
// stops warning.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>

#include <string>

#include "rosout_watch.h"
#include "test_frames.h"

namespace enc = sensor_msgs::image_encodings;
using rosgraph_msgs::Log;

namespace {

constexpr double kWaitS = 15.0;  // the launch file's input_timeout is 1 s
const std::string kRgb = "/camera/rgb/image_raw";
const std::string kDepth = "/camera/depth_registered/image_raw";

bool waitForSubscriber(const ros::Publisher& pub) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kWaitS);
  while (ros::WallTime::now() < end && pub.getNumSubscribers() < 1) ros::WallDuration(0.05).sleep();
  return pub.getNumSubscribers() > 0;
}

TEST(NoInput, SilentTopicsAreNamedUntilBothImagesArrive) {
  ros::NodeHandle nh;
  RosoutWatch watch(nh);
  const std::string both = "no image on " + kRgb + " (0 publishers) and " + kDepth + " (0 publishers)";
  ASSERT_TRUE(watch.waitFor(Log::WARN, both, 1, kWaitS)) << watch.dump();
  EXPECT_NE(watch.dump().find("rgb_topic:="), std::string::npos) << watch.dump();

  ros::Publisher rgb_pub = nh.advertise<sensor_msgs::Image>(kRgb, 1);
  ASSERT_TRUE(waitForSubscriber(rgb_pub));
  const cv::Mat rgb(480, 640, CV_8UC3, cv::Scalar(90, 120, 150));
  rgb_pub.publish(toImage(rgb, enc::BGR8, ros::Time(1000.0)));
  const std::string depth_only = "no image on " + kDepth + " (0 publishers) in";
  ASSERT_TRUE(watch.waitFor(Log::WARN, depth_only, 1, kWaitS)) << watch.dump();

  ros::Publisher depth_pub = nh.advertise<sensor_msgs::Image>(kDepth, 1);
  ASSERT_TRUE(waitForSubscriber(depth_pub));
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.0f));
  depth_pub.publish(toImage(depth, enc::TYPE_32FC1, ros::Time(1000.0)));
  ros::WallDuration(1.5).sleep();  // a warning already on its way may still come
  const size_t warnings = watch.count(Log::WARN, "no image on");
  ros::WallDuration(3.0).sleep();
  EXPECT_EQ(watch.count(Log::WARN, "no image on"), warnings) << "still warning after both images came\n"
                                                             << watch.dump();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_ros_no_input");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
