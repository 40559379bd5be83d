#pragma once
// Helpers shared by the yolo_slam nodelets (not installed).
#include <ros/ros.h>

#include <mutex>
#include <string>

#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"

namespace yolo_slam {
namespace ros1 {

// The settings file named by ~settings (ORB-SLAM2-style YAML); "" gives an empty Config, so
// every module keeps its built-in defaults. Throws yolo_slam::Error naming the file.
inline Config loadSettings(const ::ros::NodeHandle& pnh, std::string* path_out = nullptr) {
  std::string path;
  pnh.param<std::string>("settings", path, "");
  if (path_out) *path_out = path;
  return path.empty() ? Config() : Config::fromFile(path);
}

// Camera model from the settings when they hold Camera.fx, else the built-in defaults (the
// intrinsics then come from camera_info).
inline CameraModel baseCamera(const Config& cfg) {
  return cfg.has("Camera.fx") ? CameraModel::load(cfg) : CameraModel();
}

// Rate limit for per-frame errors that still shows every distinct problem at once: a message
// is logged when its text differs from the previous one or `period` seconds have passed.
class ErrorThrottle {
 public:
  explicit ErrorThrottle(double period = 1.0) : period_(period) {}
  bool shouldLog(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex_);
    const ::ros::WallTime now = ::ros::WallTime::now();
    if (what == last_ && (now - last_time_).toSec() < period_) return false;
    last_ = what;
    last_time_ = now;
    return true;
  }

 private:
  double period_;
  std::mutex mutex_;  // guards last_, last_time_ (callbacks of several threads)
  std::string last_;
  ::ros::WallTime last_time_;
};

}  // namespace ros1
}  // namespace yolo_slam
