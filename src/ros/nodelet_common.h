#pragma once
// Helpers shared by the yolo_slam nodelets (not installed).
#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <sensor_msgs/CameraInfo.h>

#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/log.h"
#include "yolo_slam/ros/conversions.h"

namespace yolo_slam {
namespace ros1 {

// The camera topics every nodelet subscribes, named as openni2_launch / rgbd_launch publish them
// (registered depth, REP 118); launch files remap them to other drivers' or bags' names.
constexpr const char* kRgbTopic = "camera/rgb/image_raw";
constexpr const char* kDepthTopic = "camera/depth_registered/image_raw";

// The core's messages (settings warnings, map resets, loop closures) to rosconsole, under the
// logger ros.yolo_slam.core, instead of stderr. Idempotent; every nodelet calls it first.
inline void routeCoreLogToRosconsole() {
  log::setSink([](log::Level level, const std::string& message) {
    switch (level) {
      case log::Level::Info: ROS_INFO_NAMED("core", "%s", message.c_str()); break;
      case log::Level::Warn: ROS_WARN_NAMED("core", "%s", message.c_str()); break;
      case log::Level::Error: ROS_ERROR_NAMED("core", "%s", message.c_str()); break;
    }
  });
}

// The settings file named by ~settings (ORB-SLAM2-style YAML); "" gives an empty Config, so
// every module keeps its built-in defaults. ~overrides, a list of "Key=value" strings, is applied
// on top before anything loads (the runner's --set). Throws yolo_slam::Error naming the file or
// the override.
inline Config loadSettings(const ::ros::NodeHandle& pnh, std::string* path_out = nullptr) {
  routeCoreLogToRosconsole();
  std::string path;
  pnh.param<std::string>("settings", path, "");
  if (path_out) *path_out = path;
  Config cfg = path.empty() ? Config() : Config::fromFile(path);
  if (!pnh.hasParam("overrides")) return cfg;
  std::vector<std::string> overrides;
  if (!pnh.getParam("overrides", overrides))
    throw Error(pnh.resolveName("overrides") + " must be a list of \"Key=value\" strings, e.g. "
                "['Screening.boxDilation=0.1']");
  for (const auto& o : overrides) cfg.setFromAssignment(o);
  return cfg;
}

// Camera model from the settings when they hold Camera.fx, else the built-in defaults (the
// intrinsics then come from camera_info).
inline CameraModel baseCamera(const Config& cfg) {
  return cfg.has("Camera.fx") ? CameraModel::load(cfg) : CameraModel();
}

// A nodelet's /diagnostics: a diagnostic_updater::Updater (hardware id yolo_slam) sent on a wall
// timer, not Updater::update's ROS-time period, so diagnostics keep coming while a bag's clock
// stands still. begin() in onInit, then add the tasks, then run(). The Updater locks inside.
class NodeletDiagnostics {
 public:
  diagnostic_updater::Updater& begin(::ros::NodeHandle& nh, ::ros::NodeHandle& pnh, const std::string& name) {
    updater_ = std::make_unique<diagnostic_updater::Updater>(nh, pnh, name);
    updater_->setHardwareID("yolo_slam");
    return *updater_;
  }
  void run(::ros::NodeHandle& nh) {
    timer_ = nh.createWallTimer(::ros::WallDuration(kPeriodS),
                                [this](const ::ros::WallTimerEvent&) { updater_->force_update(); });
  }
  void stop() { timer_.stop(); }

 private:
  static constexpr double kPeriodS = 1.0;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  ::ros::WallTimer timer_;
};

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

// Whether the nodelet's colour input (`image_topic`, resolved) is rectified: ~rectified true,
// false or auto (the default: rectified when the topic contains "image_rect"). Throws Error on
// another value.
inline bool rectifiedInput(const ::ros::NodeHandle& pnh, const std::string& image_topic) {
  bool flag = false;
  if (pnh.getParam("rectified", flag)) return flag;
  std::string mode = "auto";
  pnh.getParam("rectified", mode);
  return isRectified(parseRectified(mode), image_topic);
}

// The camera model a nodelet works with: the last CameraInfo received (bf, ThDepth and the
// rest from the settings' model), or the settings' own intrinsics when use_camera_info is
// false. `rectified`: the images are rectified (the CameraInfo's P, no distortion; see
// cameraFromInfo). configure() runs in onInit before any callback; update() and get() run on
// callback threads.
class CameraSource {
 public:
  void configure(const CameraModel& base, bool use_camera_info, bool rectified = false) {
    base_ = base;
    use_camera_info_ = use_camera_info;
    rectified_ = rectified;
  }
  // Throws Error (naming `topic`) when the CameraInfo is unusable; the last good one stays.
  void update(const sensor_msgs::CameraInfo& info, const std::string& topic) {
    CameraModel cam = cameraFromInfo(info, base_, topic, rectified_);
    std::lock_guard<std::mutex> lock(mutex_);
    cam_ = cam;
  }
  // True for a frame (image stamp) that comes before any camera_info but within
  // kFirstInfoGraceS of the first frame: a driver or bag publishes both at once and the
  // subscriptions race, so such a frame is skipped quietly rather than reported as bad input.
  bool awaitingFirstInfo(const ::ros::Time& stamp) {
    if (!use_camera_info_) return false;
    std::lock_guard<std::mutex> lock(mutex_);
    if (cam_) return false;
    if (first_stamp_.isZero() || stamp < first_stamp_) first_stamp_ = stamp;
    return (stamp - first_stamp_).toSec() < kFirstInfoGraceS;
  }
  // Throws Error when camera_info is wanted and none has arrived on `topic` yet.
  CameraModel get(const std::string& topic) const {
    if (!use_camera_info_) return base_;
    std::lock_guard<std::mutex> lock(mutex_);
    if (!cam_)
      throw Error("no camera_info received on " + topic +
                  "; publish the camera's CameraInfo or set ~use_camera_info false to take "
                  "the intrinsics from ~settings");
    return *cam_;
  }

 private:
  CameraModel base_;             // const after configure()
  bool use_camera_info_ = true;  // const after configure()
  bool rectified_ = false;       // const after configure()
  static constexpr double kFirstInfoGraceS = 1.0;
  mutable std::mutex mutex_;     // guards cam_ and first_stamp_
  std::optional<CameraModel> cam_;
  ::ros::Time first_stamp_;      // the first frame asked about before any camera_info
};

}  // namespace ros1
}  // namespace yolo_slam
