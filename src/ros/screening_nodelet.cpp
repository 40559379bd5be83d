// yolo_slam/Screening: pairs colour, depth and boxes by stamp (message_filters approximate
// time), extracts ORB features, marks dynamic keypoints with depth-RANSAC inside the person
// boxes and publishes one KeypointFrame per RGB-D pair. Frames the synchroniser drops are
// counted (never silent): a warning per drop burst and a /diagnostics status every second.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/synchronizer.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <deque>
#include <memory>
#include <mutex>

#include "nodelet_common.h"
#include "yolo_slam/BoundingBoxes.h"
#include "yolo_slam/KeypointFrame.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/ros/conversions.h"
#include "yolo_slam/screening/pipeline.h"
#include "yolo_slam/screening/screener.h"

namespace yolo_slam {
namespace ros1 {

using sensor_msgs::Image;
using sensor_msgs::ImageConstPtr;
namespace sp = message_filters::sync_policies;

class ScreeningNodelet : public nodelet::Nodelet {
 private:
  using Sync3 = message_filters::Synchronizer<sp::ApproximateTime<Image, Image, BoundingBoxes>>;
  using Sync2 = message_filters::Synchronizer<sp::ApproximateTime<Image, Image>>;

  void onInit() override {
    ::ros::NodeHandle& nh = getNodeHandle();
    ::ros::NodeHandle& pnh = getPrivateNodeHandle();
    int queue_size = 100;
    pnh.param("queue_size", queue_size, 100);
    pnh.param("use_boxes", use_boxes_, true);
    pnh.param("use_camera_info", use_camera_info_, true);
    pnh.param("depth_factor_16u", depth_factor_16u_, 1000.0);
    double max_interval = 0.05;
    pnh.param("sync_max_interval", max_interval, 0.05);
    try {
      const Config cfg = loadSettings(pnh);
      camera_.configure(baseCamera(cfg), use_camera_info_);
      orb_ = std::make_unique<features::OrbExtractor>(features::OrbOptions::load(cfg));
      screening::ScreeningOptions sopt = screening::ScreeningOptions::load(cfg);
      std::string mode;
      if (pnh.getParam("dynamic_mode", mode)) sopt.mode = screening::parseDynamicMode(mode);
      // As System::trackRgbd; without the detector's topic there are no boxes to track.
      if (!use_boxes_) sopt.tracker.enabled = false;
      screening_ = std::make_unique<screening::ScreeningPipeline>(sopt);
      NODELET_INFO("Screening: %d ORB features, dynamic mode %s, %s, queue %d",
                   orb_->options().n_features, screening::toString(sopt.mode).c_str(),
                   use_boxes_ ? "rgb+depth+boxes" : "rgb+depth (no detector)", queue_size);
    } catch (const std::exception& e) {
      NODELET_ERROR("Screening: bad settings: %s. The nodelet is idle until restarted with "
                    "valid ~settings", e.what());
      return;
    }

    pub_ = nh.advertise<KeypointFrame>("yolo_slam/keypoint_frame", queue_size);
    diag_pub_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 10);
    // Multi-threaded handle: camera_info is stored even while a frame is being processed.
    info_sub_ = getMTNodeHandle().subscribe("camera/rgb/camera_info", 10, &ScreeningNodelet::onInfo, this);
    rgb_sub_.subscribe(nh, "camera/rgb/image_color", queue_size);
    depth_sub_.subscribe(nh, "camera/depth/image", queue_size);
    rgb_sub_.registerCallback(&ScreeningNodelet::onRgbArrived, this);
    if (use_boxes_) {
      boxes_sub_.subscribe(nh, "yolo_slam/boxes", queue_size);
      sync3_ = std::make_unique<Sync3>(sp::ApproximateTime<Image, Image, BoundingBoxes>(queue_size),
                                       rgb_sub_, depth_sub_, boxes_sub_);
      sync3_->setMaxIntervalDuration(::ros::Duration(max_interval));
      sync3_->registerCallback(&ScreeningNodelet::onFrame3, this);
    } else {
      sync2_ = std::make_unique<Sync2>(sp::ApproximateTime<Image, Image>(queue_size), rgb_sub_,
                                       depth_sub_);
      sync2_->setMaxIntervalDuration(::ros::Duration(max_interval));
      sync2_->registerCallback(&ScreeningNodelet::onFrame2, this);
    }
    diag_timer_ = nh.createWallTimer(::ros::WallDuration(1.0),
                                     [this](const ::ros::WallTimerEvent&) { publishDiagnostics(); });
  }

  void onInfo(const sensor_msgs::CameraInfoConstPtr& info) {
    try {
      camera_.update(*info, info_sub_.getTopic());
    } catch (const std::exception& e) {
      NODELET_ERROR_THROTTLE(5.0, "Screening: %s", e.what());
    }
  }

  // Every colour image is noted so frames the synchroniser never emits can be counted.
  void onRgbArrived(const ImageConstPtr& img) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++rgb_received_;
    pending_rgb_.push_back(img->header.stamp);
    if (pending_rgb_.size() > 10000) pending_rgb_.pop_front();
  }

  void onFrame2(const ImageConstPtr& rgb, const ImageConstPtr& depth) {
    process(rgb, depth, nullptr);
  }
  void onFrame3(const ImageConstPtr& rgb, const ImageConstPtr& depth,
                const BoundingBoxes::ConstPtr& boxes) {
    process(rgb, depth, boxes);
  }

  CameraModel camera() { return camera_.get(info_sub_.getTopic()); }

  void process(const ImageConstPtr& rgb, const ImageConstPtr& depth,
               const BoundingBoxes::ConstPtr& boxes_msg) {
    size_t dropped_now = 0;
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++synced_;
      // The synchroniser emits in stamp order: colour images older than this one were dropped.
      while (!pending_rgb_.empty() && pending_rgb_.front() <= rgb->header.stamp) {
        if (pending_rgb_.front() < rgb->header.stamp) ++dropped_now;
        pending_rgb_.pop_front();
      }
      dropped_ += dropped_now;
    }
    if (dropped_now > 0)
      NODELET_WARN("Screening: the synchroniser dropped %zu colour frame(s) before %.3f (%zu in "
                   "total); raise ~queue_size or play the bag slower", dropped_now,
                   rgb->header.stamp.toSec(), dropped_.load());
    try {
      Stopwatch sw;
      CameraModel cam = camera();
      bool is_rgb = true;
      const cv::Mat image = imageView(*rgb, rgb_sub_.getTopic(), is_rgb);
      const cv::Mat depth_m = depthToMetres(*depth, depth_sub_.getTopic(), depth_factor_16u_);
      if (depth_m.size() != image.size())
        throw Error("depth image on " + depth_sub_.getTopic() + " is " +
                    std::to_string(depth_m.cols) + "x" + std::to_string(depth_m.rows) +
                    " but the colour image is " + std::to_string(image.cols) + "x" +
                    std::to_string(image.rows) + "; use registered depth");
      if (image.cols != cam.width || image.rows != cam.height)
        throw Error("image size " + std::to_string(image.cols) + "x" +
                    std::to_string(image.rows) + " differs from the calibration (" +
                    std::to_string(cam.width) + "x" + std::to_string(cam.height) + ")");
      cam.rgb_order = is_rgb;
      features::FeatureFrame frame =
          features::buildFeatureFrame(*orb_, cam, image, depth_m, rgb->header.stamp.toSec());
      detection::Boxes boxes;
      if (boxes_msg) boxes = boxesFromMsg(boxes_msg->boxes);
      boxes = screening_->process(frame, boxes, cam, depth_m).boxes;  // + boxes carried by the tracker
      auto out = boost::make_shared<KeypointFrame>();
      out->header = rgb->header;
      out->depth_stamp = depth->header.stamp;
      out->index = static_cast<uint32_t>(++index_);
      toMsg(frame, boxes, *out);
      pub_.publish(out);
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++published_;
      ms_.push_back(sw.ms());
      if (ms_.size() > 1000) ms_.erase(ms_.begin(), ms_.begin() + 500);
    } catch (const std::exception& e) {
      ++rejected_;
      if (throttle_.shouldLog(e.what()))
        NODELET_ERROR("Screening: frame %.3f rejected: %s", rgb->header.stamp.toSec(), e.what());
    }
  }

  void publishDiagnostics() {
    diagnostic_msgs::DiagnosticStatus st;
    st.name = getName() + ": frames";
    st.hardware_id = "yolo_slam";
    Summary s;
    size_t rgb = 0, synced = 0, published = 0;
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      s = summarize(ms_);
      rgb = rgb_received_;
      synced = synced_;
      published = published_;
    }
    const size_t dropped = dropped_, rejected = rejected_;
    st.level = dropped + rejected > 0 ? diagnostic_msgs::DiagnosticStatus::WARN
                                      : diagnostic_msgs::DiagnosticStatus::OK;
    st.message = dropped + rejected > 0
                     ? std::to_string(dropped) + " dropped, " + std::to_string(rejected) + " rejected"
                     : "no frame dropped";
    auto kv = [&](const std::string& k, const std::string& v) {
      diagnostic_msgs::KeyValue p;
      p.key = k;
      p.value = v;
      st.values.push_back(p);
    };
    kv("rgb_received", std::to_string(rgb));
    kv("synchronised", std::to_string(synced));
    kv("published", std::to_string(published));
    kv("dropped_by_sync", std::to_string(dropped));
    kv("rejected_bad_input", std::to_string(rejected));
    kv("median_ms", std::to_string(s.median));
    diagnostic_msgs::DiagnosticArray arr;
    arr.header.stamp = ::ros::Time::now();
    arr.status.push_back(st);
    diag_pub_.publish(arr);
  }

  bool use_boxes_ = true, use_camera_info_ = true;
  ErrorThrottle throttle_;
  double depth_factor_16u_ = 1000.0;
  std::unique_ptr<features::OrbExtractor> orb_;    // const after onInit (thread-safe extract)
  // Box tracking, Algorithm 1, label propagation: stateful, used by the frame callback only
  // (the synchroniser serialises it, like index_).
  std::unique_ptr<screening::ScreeningPipeline> screening_;

  CameraSource camera_;  // camera_info callback vs frame callback: locks inside

  std::mutex stats_mutex_;  // guards the counters below, pending_rgb_ and ms_
  size_t rgb_received_ = 0, synced_ = 0, published_ = 0;
  std::deque<::ros::Time> pending_rgb_;
  std::vector<double> ms_;
  std::atomic<size_t> dropped_{0}, rejected_{0};
  uint32_t index_ = 0;  // frame callback only (the synchroniser serialises it)

  message_filters::Subscriber<Image> rgb_sub_, depth_sub_;
  message_filters::Subscriber<BoundingBoxes> boxes_sub_;
  std::unique_ptr<Sync3> sync3_;
  std::unique_ptr<Sync2> sync2_;
  ::ros::Subscriber info_sub_;
  ::ros::Publisher pub_, diag_pub_;
  ::ros::WallTimer diag_timer_;
};

}  // namespace ros1
}  // namespace yolo_slam

PLUGINLIB_EXPORT_CLASS(yolo_slam::ros1::ScreeningNodelet, nodelet::Nodelet)
