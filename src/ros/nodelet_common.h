#pragma once
// Helpers shared by the yolo_slam nodelets (not installed).
#include <ros/ros.h>

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

}  // namespace ros1
}  // namespace yolo_slam
