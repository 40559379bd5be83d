// Without a camera the OpenNI2Camera nodelet must say so clearly, retry on its timer and keep
// running (its manager stays up and it keeps its topics advertised).
#include <gtest/gtest.h>
#include <ros/master.h>
#include <ros/ros.h>

#include <map>

#include "rosout_watch.h"

TEST(OpenNI2Camera, NoDeviceLogsErrorAndRetries) {
  ros::NodeHandle nh;
  RosoutWatch watch(nh);
  // Retry period 0.5 s in the .test file: three attempts within a few seconds.
  ASSERT_TRUE(watch.waitFor(rosgraph_msgs::Log::ERROR, "no OpenNI2 device found", 3, 20.0))
      << watch.dump();
  EXPECT_GE(watch.count(rosgraph_msgs::Log::ERROR, "retrying in 0.5 s"), 3u) << watch.dump();
  EXPECT_EQ(watch.count(rosgraph_msgs::Log::FATAL, ""), 0u) << watch.dump();
  // Still alive: the manager keeps the camera topics advertised.
  ros::master::V_TopicInfo topics;
  ASSERT_TRUE(ros::master::getTopics(topics));
  // openni2_launch's names and types.
  std::map<std::string, std::string> advertised;
  for (const auto& t : topics) advertised[t.name] = t.datatype;
  EXPECT_EQ(advertised["/camera/rgb/image_raw"], "sensor_msgs/Image");
  EXPECT_EQ(advertised["/camera/rgb/camera_info"], "sensor_msgs/CameraInfo");
  EXPECT_EQ(advertised["/camera/depth_registered/image_raw"], "sensor_msgs/Image");
  EXPECT_EQ(advertised["/camera/depth_registered/image"], "sensor_msgs/Image");
  EXPECT_EQ(advertised["/camera/depth_registered/camera_info"], "sensor_msgs/CameraInfo");
  std::vector<std::string> nodes;
  ASSERT_TRUE(ros::master::getNodes(nodes));
  EXPECT_NE(std::find(nodes.begin(), nodes.end(), "/camera_manager"), nodes.end());
}

TEST(OpenNI2Camera, MissingRecordingNamesTheFile) {
  ros::NodeHandle nh;
  RosoutWatch watch(nh);
  ASSERT_TRUE(watch.waitFor(rosgraph_msgs::Log::ERROR, "/nonexistent/recording.oni", 1, 20.0))
      << watch.dump();
}

TEST(OpenNI2Camera, MissingNthDeviceSaysHowManyThereAre) {
  ros::NodeHandle nh;
  RosoutWatch watch(nh);
  ASSERT_TRUE(watch.waitFor(rosgraph_msgs::Log::ERROR, "no OpenNI2 device #2 (0 connected)", 1, 20.0))
      << watch.dump();
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_ros_openni2_no_device");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
