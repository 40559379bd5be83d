// Zero-copy inside one nodelet manager: the sink nodelet must receive the very object the
// source nodelet published (same address), for every message.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_msgs/String.h>

#include <mutex>

std::mutex g_mutex;  // guards g_reports (subscriber thread vs test thread)
std::vector<std::string> g_reports;

TEST(ZeroCopy, SinkReceivesThePublishedObject) {
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe<std_msgs::String>(
      "yolo_slam/zero_copy_report", 100, +[](const std_msgs::String::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(g_mutex);
        g_reports.push_back(m->data);
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(20.0);
  while (ros::ok() && ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_reports.size() >= 30) break;
    }
    ros::WallDuration(0.05).sleep();
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  ASSERT_GE(g_reports.size(), 30u) << "the probe nodelets did not report";
  for (const auto& r : g_reports) {
    EXPECT_EQ(r.rfind("same ", 0), 0u) << r;
    EXPECT_NE(r.find(" intact"), std::string::npos) << r;
  }
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_ros_zero_copy");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
