#pragma once
// Test helper: collects /rosout (the nodes publish there directly; no rosout node needed) so a test can assert that a nodelet logged a clear error.
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>

#include <mutex>
#include <string>
#include <vector>

class RosoutWatch {
 public:
  explicit RosoutWatch(ros::NodeHandle& nh)
      : sub_(nh.subscribe("/rosout", 1000, &RosoutWatch::onLog, this)) {}

  // Number of messages at `level` (rosgraph_msgs::Log::ERROR, ...) whose text contains `needle`.
  size_t count(uint8_t level, const std::string& needle) const {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t n = 0;
    for (const auto& l : logs_)
      if (l.level == level && l.msg.find(needle) != std::string::npos) ++n;
    return n;
  }

  // Spins (the caller runs an AsyncSpinner) until count(level, needle) >= n or the timeout.
  bool waitFor(uint8_t level, const std::string& needle, size_t n, double timeout_s) const {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (ros::ok() && ros::WallTime::now() < end) {
      if (count(level, needle) >= n) return true;
      ros::WallDuration(0.02).sleep();
    }
    return count(level, needle) >= n;
  }

  std::string dump() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::string s;
    for (const auto& l : logs_) s += "[" + std::to_string(l.level) + "] " + l.name + ": " + l.msg + "\n";
    return s;
  }

 private:
  void onLog(const rosgraph_msgs::Log::ConstPtr& l) {
    std::lock_guard<std::mutex> lock(mutex_);
    logs_.push_back(*l);
  }
  mutable std::mutex mutex_;  // guards logs_ (subscriber thread vs test thread)
  std::vector<rosgraph_msgs::Log> logs_;
  ros::Subscriber sub_;
};
