// yolo_slam/Screening: pairs colour and depth by stamp (message_filters approximate time),
// extracts ORB features, marks dynamic keypoints with depth-RANSAC inside the person boxes and
// publishes one KeypointFrame per RGB-D pair. Boxes are asynchronous by default
// (Detection.async): a frame never waits for its own detection, it takes the newest boxes
// message not used before if it is at most Detection.maxAge older than the frame, and the box
// tracker carries boxes in between. With Detection.async 0 colour, depth and boxes are
// synchronised (every frame waits for its detection, the paper's pipeline). Frames the
// synchroniser drops are counted (never silent): a warning per drop burst and a /diagnostics
// status every second. Until both images have arrived once, a warning every ~input_timeout
// seconds names the topic that stays silent (wrong topic names, or no camera driver).
#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <dynamic_reconfigure/server.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/synchronizer.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <atomic>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>

#include "nodelet_common.h"
#include "yolo_slam/BoundingBoxes.h"
#include "yolo_slam/KeypointFrame.h"
#include "yolo_slam/ScreeningConfig.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/detection/async_detector.h"
#include "yolo_slam/frontend/front_end.h"
#include "yolo_slam/ros/conversions.h"

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
    pnh.param("assume_registered", assume_registered_, false);
    double max_interval = 0.05;
    pnh.param("sync_max_interval", max_interval, 0.05);
    pnh.param("sync_min_period", sync_min_period_, kDefaultSyncMinPeriodS);
    pnh.param("input_timeout", input_timeout_s_, kDefaultInputTimeoutS);
    if (!configure(nh, pnh, queue_size)) return;
    pub_ = nh.advertise<KeypointFrame>("yolo_slam/keypoint_frame", queue_size);
    startDiagnostics(nh, pnh);
    subscribeInputs(nh, queue_size, max_interval);
    reconfigure_ = std::make_unique<ReconfigureServer>(reconfigure_mutex_, pnh);
    reconfigure_->setCallback([this](ScreeningConfig& c, uint32_t) { onReconfigure(c); });
  }

  // The settings file and the parameters that override it. False (logged) when they are bad: the
  // nodelet then stays idle.
  bool configure(::ros::NodeHandle& nh, ::ros::NodeHandle& pnh, int queue_size) {
    try {
      const Config cfg = loadSettings(pnh);
      const bool rectified = rectifiedInput(pnh, nh.resolveName(kRgbTopic));
      camera_.configure(baseCamera(cfg), use_camera_info_, rectified);
      screening_options_ = screening::ScreeningOptions::load(cfg);
      std::string mode;
      if (pnh.getParam("dynamic_mode", mode)) screening_options_.mode = screening::parseDynamicMode(mode);
      else pnh.setParam("dynamic_mode", screening::toString(screening_options_.mode));  // the reconfigure start value
      // As System::trackRgbd; without the detector's topic there are no boxes to track.
      if (!use_boxes_) screening_options_.tracker.enabled = false;
      orb_options_ = features::OrbOptions::load(cfg);
      front_end_ = std::make_unique<frontend::FrontEnd>(orb_options_, screening_options_);
      detection::AsyncDetectionOptions aopt = detection::AsyncDetectionOptions::load(cfg);
      pnh.param("async_detection", aopt.enabled, aopt.enabled);
      async_boxes_ = use_boxes_ && aopt.enabled;
      box_feed_ = std::make_unique<detection::BoxFeed>(aopt.max_age_s);
      NODELET_INFO("Screening: %d ORB features, dynamic mode %s, %s, queue %d, %s images",
                   front_end_->extractor().options().n_features, screening::toString(screening_options_.mode).c_str(),
                   !use_boxes_ ? "rgb+depth (no detector)"
                   : async_boxes_ ? "rgb+depth, newest boxes (async)" : "rgb+depth+boxes synchronised",
                   queue_size, rectified ? "rectified" : "raw");
      return true;
    } catch (const std::exception& e) {
      NODELET_ERROR("Screening: bad settings: %s. The nodelet is idle until restarted with "
                    "valid ~settings", e.what());
      return false;
    }
  }

  void startDiagnostics(::ros::NodeHandle& nh, ::ros::NodeHandle& pnh) {
    diagnostic_updater::Updater& updater = diagnostics_.begin(nh, pnh, getName());
    updater.add("frames", this, &ScreeningNodelet::fillDiagnostics);
    rate_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
        diagnostic_updater::FrequencyStatusParam(&min_rate_hz_, &max_rate_hz_), "published frame rate");
    updater.add(*rate_);
    diagnostics_.run(nh);
  }

  // Camera info, colour and depth, and the boxes: synchronised with each frame (every-frame
  // detection) or the newest kept aside (asynchronous detection, or none without a detector).
  void subscribeInputs(::ros::NodeHandle& nh, int queue_size, double max_interval) {
    // Multi-threaded handle: camera_info is stored even while a frame is being processed.
    info_sub_ = getMTNodeHandle().subscribe("camera/rgb/camera_info", 10, &ScreeningNodelet::onInfo, this);
    rgb_sub_.subscribe(nh, kRgbTopic, queue_size);
    depth_sub_.subscribe(nh, kDepthTopic, queue_size);
    rgb_sub_.registerCallback(&ScreeningNodelet::onRgbArrived, this);
    depth_sub_.registerCallback(&ScreeningNodelet::onDepthArrived, this);
    if (input_timeout_s_ > 0)
      input_watch_ = nh.createWallTimer(::ros::WallDuration(input_timeout_s_),
                                        [this](const ::ros::WallTimerEvent&) { warnIfNoInput(); });
    if (async_boxes_) {
      // Multi-threaded handle: boxes are stored while a frame is being processed.
      async_boxes_sub_ = getMTNodeHandle().subscribe("yolo_slam/boxes", kBoxesQueue, &ScreeningNodelet::onBoxes, this);
    }
    if (use_boxes_ && !async_boxes_) {
      boxes_sub_.subscribe(nh, "yolo_slam/boxes", queue_size);
      sync3_ = std::make_unique<Sync3>(sp::ApproximateTime<Image, Image, BoundingBoxes>(queue_size),
                                       rgb_sub_, depth_sub_, boxes_sub_);
      sync3_->setMaxIntervalDuration(::ros::Duration(max_interval));
      sync3_->registerCallback(&ScreeningNodelet::onFrame3, this);
    } else {
      sync2_ = std::make_unique<Sync2>(sp::ApproximateTime<Image, Image>(queue_size), rgb_sub_,
                                       depth_sub_);
      sync2_->setMaxIntervalDuration(::ros::Duration(max_interval));
      // Knowing that images come at least this far apart, the synchroniser emits a pair as soon
      // as both images are there, instead of holding it until the next frame proves it best.
      if (sync_min_period_ > 0) sync2_->setInterMessageLowerBound(::ros::Duration(sync_min_period_));
      sync2_->registerCallback(&ScreeningNodelet::onFrame2, this);
    }
  }

  // cfg/Screening.cfg. Runs on the nodelet's single-threaded queue, as the frame callbacks: the
  // front end is rebuilt between two frames (its box tracks and feature budget start afresh).
  void onReconfigure(ScreeningConfig& c) {
    screening::DynamicMode mode;
    try {
      mode = screening::parseDynamicMode(c.dynamic_mode);
    } catch (const std::exception& e) {
      NODELET_ERROR("Screening: %s; keeping %s", e.what(), screening::toString(screening_options_.mode).c_str());
      c.dynamic_mode = screening::toString(screening_options_.mode);
      return;
    }
    if (mode == screening_options_.mode) return;
    screening_options_.mode = mode;
    front_end_ = std::make_unique<frontend::FrontEnd>(orb_options_, screening_options_);
    NODELET_INFO("Screening: dynamic mode %s", c.dynamic_mode.c_str());
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

  void onDepthArrived(const ImageConstPtr&) { depth_arrived_ = true; }

  // Before the first colour and depth image: which topic is silent, and who publishes it.
  void warnIfNoInput() {
    size_t rgb = 0;
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      rgb = rgb_received_;
    }
    const bool depth = depth_arrived_;
    if (rgb > 0 && depth) {
      input_watch_.stop();
      return;
    }
    silent_s_ += input_timeout_s_;
    std::string silent;
    for (const auto* sub : {rgb > 0 ? nullptr : &rgb_sub_, depth ? nullptr : &depth_sub_}) {
      if (!sub) continue;
      if (!silent.empty()) silent += " and ";
      const ::ros::Subscriber& raw = sub->getSubscriber();
      silent += raw.getTopic() + " (" + std::to_string(raw.getNumPublishers()) + " publishers)";
    }
    NODELET_WARN("Screening: no image on %s in %.0f s: check that the camera driver or bag publishes "
                 "there (rostopic list), or remap with rgb_topic:= / depth_topic:=", silent.c_str(), silent_s_);
  }

  void onFrame2(const ImageConstPtr& rgb, const ImageConstPtr& depth) {
    process(rgb, depth, nullptr);
  }
  void onBoxes(const BoundingBoxes::ConstPtr& msg) {
    detection::DetectionResult r;
    r.stamp = msg->header.stamp.toSec();
    r.boxes = boxesFromMsg(msg->boxes);
    std::lock_guard<std::mutex> lock(boxes_mutex_);
    r.frame = ++boxes_received_;
    newest_boxes_ = std::move(r);
  }
  // The boxes of a frame: synchronised ones, or the newest asynchronous result if fresh.
  detection::FrameBoxes boxesFor(const ::ros::Time& stamp, const BoundingBoxes::ConstPtr& synced) {
    detection::FrameBoxes fixed;
    fixed.fresh = true;  // synchronised boxes, or none at all: the detector's verdict on this frame
    if (synced) fixed.boxes = boxesFromMsg(synced->boxes);
    if (synced || !async_boxes_) return fixed;
    std::optional<detection::DetectionResult> newest;
    {
      std::lock_guard<std::mutex> lock(boxes_mutex_);
      newest = newest_boxes_;
    }
    const long expired_before = box_feed_->expired();
    detection::FrameBoxes fb = box_feed_->take(newest, stamp.toSec());
    boxes_too_old_ += box_feed_->expired() - expired_before;
    if (fb.fresh) ++frames_with_new_boxes_;
    return fb;
  }
  void onFrame3(const ImageConstPtr& rgb, const ImageConstPtr& depth,
                const BoundingBoxes::ConstPtr& boxes) {
    process(rgb, depth, boxes);
  }

  CameraModel camera() { return camera_.get(info_sub_.getTopic()); }

  // Depth must be registered to colour (pixel for pixel). A driver marks registered depth with
  // the colour frame id (openni2_launch's depth_registered topics); plain depth/ topics carry
  // the depth camera's frame and would be screened wrongly without a word.
  void checkRegistered(const Image& rgb, const Image& depth) const {
    if (assume_registered_) return;
    auto bare = [](std::string f) {
      while (!f.empty() && f.front() == '/') f.erase(0, 1);
      return f;
    };
    if (bare(rgb.header.frame_id) == bare(depth.header.frame_id)) return;
    throw Error("depth on " + depth_sub_.getTopic() + " is in frame '" + depth.header.frame_id + "', colour on " +
                rgb_sub_.getTopic() + " in '" + rgb.header.frame_id +
                "': depth is not registered to colour. Use the driver's registered depth (openni2_launch: "
                "depth_registered:=true, topic camera/depth_registered/image_raw), or set ~assume_registered true "
                "if the images are registered under other frame names (TUM bags)");
  }

  // A frame screened before any detection arrived would start the map with people in it: held
  // back (not published), for at most kAwaitMaxS of stream time. A Detector that never answers
  // must not stop the graph: after that, frames go on without boxes, with a warning.
  bool holdBack(const ::ros::Time& stamp) {
    if (first_stamp_.isZero() || stamp < first_stamp_) first_stamp_ = stamp;
    const double waited_s = (stamp - first_stamp_).toSec();
    if (waited_s < kAwaitMaxS) {
      ++awaiting_detection_;
      return true;
    }
    NODELET_WARN_THROTTLE(kWarnPeriodS, "Screening: no boxes on %s %.1f s after the first frame; screening "
                          "without them. Is the Detector running? (detector:=false turns boxes off)",
                          async_boxes_sub_.getTopic().c_str(), waited_s);
    return false;
  }

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
      NODELET_WARN_THROTTLE(kWarnPeriodS, "Screening: the synchroniser dropped %zu colour frame(s) before %.3f "
                            "(%zu in total); raise ~queue_size or play the bag slower", dropped_now,
                            rgb->header.stamp.toSec(), dropped_.load());
    if (camera_.awaitingFirstInfo(rgb->header.stamp)) {
      ++awaiting_camera_info_;
      return;
    }
    try {
      Stopwatch sw;
      CameraModel cam = camera();
      bool is_rgb = true;
      const cv::Mat image = imageView(*rgb, rgb_sub_.getTopic(), is_rgb);
      const cv::Mat depth_m = depthToMetres(*depth, depth_sub_.getTopic(), depth_factor_16u_);
      checkRegistered(*rgb, *depth);
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
      const detection::FrameBoxes boxes = boxesFor(rgb->header.stamp, boxes_msg);
      const frontend::FrontEndResult fe =
          front_end_->process(image, depth_m, rgb->header.stamp.toSec(), boxes.boxes, cam, boxes.fresh);
      // A frame screened before any detection came would start the map with people in it.
      if (fe.awaiting_detection && holdBack(rgb->header.stamp)) return;
      auto out = boost::make_shared<KeypointFrame>();
      out->header = rgb->header;
      out->depth_stamp = depth->header.stamp;
      out->index = static_cast<uint32_t>(++index_);
      toMsg(fe.frame, fe.boxes, *out);  // the boxes screened: detections and carried ones
      pub_.publish(out);
      rate_->tick();
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++published_;
      ms_.push_back(sw.ms());
      extraction_ms_.push_back(fe.stats.extraction_ms);
      screening_ms_.push_back(fe.stats.screening_ms);
      for (auto* v : {&ms_, &extraction_ms_, &screening_ms_})
        if (v->size() > kTimingWindow) v->erase(v->begin(), v->begin() + kTimingWindow / 2);
    } catch (const std::exception& e) {
      ++rejected_;
      if (throttle_.shouldLog(e.what()))
        NODELET_ERROR("Screening: frame %.3f rejected: %s", rgb->header.stamp.toSec(), e.what());
    }
  }

  void fillDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& st) {
    Summary s, ext, scr;
    size_t rgb = 0, synced = 0, published = 0;
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      s = summarize(ms_);
      ext = summarize(extraction_ms_);
      scr = summarize(screening_ms_);
      rgb = rgb_received_;
      synced = synced_;
      published = published_;
    }
    const size_t dropped = dropped_, rejected = rejected_;
    if (dropped + rejected > 0)
      st.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                 std::to_string(dropped) + " dropped, " + std::to_string(rejected) + " rejected");
    else
      st.summary(diagnostic_msgs::DiagnosticStatus::OK, "no frame dropped");
    st.add("rgb_received", rgb);
    st.add("synchronised", synced);
    st.add("published", published);
    st.add("dropped_by_sync", dropped);
    st.add("rejected_bad_input", rejected);
    st.add("awaiting_camera_info", awaiting_camera_info_.load());
    st.add("median_ms", s.median);
    st.add("extraction_median_ms", ext.median);
    st.add("screening_median_ms", scr.median);
    st.add("boxes", !use_boxes_ ? "none" : async_boxes_ ? "async" : "synchronised");
    if (async_boxes_) {
      st.add("boxes_received", boxesReceived());
      st.add("frames_with_new_boxes", frames_with_new_boxes_.load());
      st.add("boxes_too_old", boxes_too_old_.load());
      st.add("awaiting_detection", awaiting_detection_.load());
    }
  }

  long boxesReceived() {
    std::lock_guard<std::mutex> lock(boxes_mutex_);
    return boxes_received_;
  }

  using ReconfigureServer = dynamic_reconfigure::Server<ScreeningConfig>;
  // openni2_launch's names: colour, and depth registered to it (16UC1 mm or 32FC1 m).
  static constexpr int kBoxesQueue = 5;             // boxes are small; a few in flight
  static constexpr double kWarnPeriodS = 2.0;       // per-frame warnings at most this often
  // Colour and depth come at least this far apart (seconds): true of every camera up to 50 Hz.
  static constexpr double kDefaultSyncMinPeriodS = 0.02;
  double sync_min_period_ = kDefaultSyncMinPeriodS;  // ~sync_min_period, const after onInit
  // ~input_timeout: seconds without the first colour or depth image between warnings (0: none).
  static constexpr double kDefaultInputTimeoutS = 10.0;
  double input_timeout_s_ = kDefaultInputTimeoutS;
  ::ros::WallTimer input_watch_;  // warnIfNoInput, on the nodelet's queue
  double silent_s_ = 0;           // warnIfNoInput only
  std::atomic<bool> depth_arrived_{false};
  static constexpr double kAwaitMaxS = 2.0;         // longest wait for the first detection
  static constexpr size_t kTimingWindow = 1000;     // timing samples kept for diagnostics
  bool use_boxes_ = true, use_camera_info_ = true;
  bool async_boxes_ = true;  // set in onInit
  // The newest boxes message (boxes callback vs frame callback).
  std::mutex boxes_mutex_;  // guards newest_boxes_, boxes_received_
  std::optional<detection::DetectionResult> newest_boxes_;
  long boxes_received_ = 0;
  // Which result each frame gets (frame callback only, serialised by the synchroniser).
  std::unique_ptr<detection::BoxFeed> box_feed_;
  std::atomic<long> frames_with_new_boxes_{0}, boxes_too_old_{0};
  // Frames not published because no detection had arrived yet (FrontEndResult::awaiting_detection),
  // and the stamp of the first frame (frame callback only).
  std::atomic<long> awaiting_detection_{0};
  // Frames skipped because they came just before the first camera_info (CameraSource).
  std::atomic<long> awaiting_camera_info_{0};
  ::ros::Time first_stamp_;
  ErrorThrottle throttle_;
  double depth_factor_16u_ = 1000.0;
  bool assume_registered_ = false;  // skip the depth/colour frame id check
  // Extraction and screening (stateful between frames), and the options it is rebuilt from: used
  // by the frame callback and the reconfigure callback, both on the nodelet's single-threaded
  // queue, like index_.
  features::OrbOptions orb_options_;
  screening::ScreeningOptions screening_options_;
  std::unique_ptr<frontend::FrontEnd> front_end_;
  boost::recursive_mutex reconfigure_mutex_;  // dynamic_reconfigure's own config lock
  std::unique_ptr<ReconfigureServer> reconfigure_;

  CameraSource camera_;  // camera_info callback vs frame callback: locks inside

  std::mutex stats_mutex_;  // guards the counters below, pending_rgb_ and the timing samples
  size_t rgb_received_ = 0, synced_ = 0, published_ = 0;
  std::deque<::ros::Time> pending_rgb_;
  std::vector<double> ms_, extraction_ms_, screening_ms_;
  std::atomic<size_t> dropped_{0}, rejected_{0};
  uint32_t index_ = 0;  // frame callback only (the synchroniser serialises it)

  message_filters::Subscriber<Image> rgb_sub_, depth_sub_;
  message_filters::Subscriber<BoundingBoxes> boxes_sub_;
  std::unique_ptr<Sync3> sync3_;
  std::unique_ptr<Sync2> sync2_;
  ::ros::Subscriber info_sub_, async_boxes_sub_;
  ::ros::Publisher pub_;
  // Published frame rate outside these bounds is a warning (a camera gives 30 Hz).
  // (FrequencyStatus keeps pointers to them and may read them at any update.)
  double min_rate_hz_ = 5.0, max_rate_hz_ = 60.0;
  // Diagnostics on /diagnostics: the counters above (the fill callback reads them under
  // stats_mutex_ or as atomics) and the published frame rate (FrequencyStatus locks inside).
  NodeletDiagnostics diagnostics_;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> rate_;
};

}  // namespace ros1
}  // namespace yolo_slam

PLUGINLIB_EXPORT_CLASS(yolo_slam::ros1::ScreeningNodelet, nodelet::Nodelet)
