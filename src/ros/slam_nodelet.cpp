// yolo_slam/Slam: tracking + mapping on the screened keypoint frames. Pose, odometry and tf follow
// REP 103 / REP 105 (pose_output.h); also the path, the static map points, keyframes with
// covisibility edges and a debug image; services reset, save_trajectory (TUM format),
// set_localization_mode, save_map and load_map (map files).
#include <cv_bridge/cv_bridge.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/PoseStamped.h>
#include <image_transport/image_transport.h>
#include <message_filters/cache.h>
#include <message_filters/subscriber.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Path.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/image_encodings.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>
#include <opencv2/imgproc.hpp>

#include <atomic>
#include <limits>
#include <memory>
#include <mutex>

#include "dense_map_publisher.h"
#include "map_messages.h"
#include "nodelet_common.h"
#include "pose_output.h"
#include "yolo_slam/KeypointFrame.h"
#include "yolo_slam/MapFile.h"
#include "yolo_slam/SaveTrajectory.h"
#include "yolo_slam/SlamConfig.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/io/trajectory.h"
#include "yolo_slam/ros/conversions.h"
#include "yolo_slam/slam/system.h"
#include "yolo_slam/vocabulary/vocabulary.h"

namespace yolo_slam {
namespace ros1 {

namespace {

const char* stateName(slam::TrackingState s) {
  switch (s) {
    case slam::TrackingState::NotInitialized: return "not initialised";
    case slam::TrackingState::Ok: return "ok";
    case slam::TrackingState::Lost: return "lost";
  }
  return "?";
}

}  // namespace

class SlamNodelet : public nodelet::Nodelet {
 public:
  ~SlamNodelet() override {
    map_timer_.stop();
    diagnostics_.stop();
    dense_timer_.stop();
    std::lock_guard<std::mutex> lock(system_mutex_);
    if (!system_) return;
    if (!trajectory_path_.empty()) {
      try {
        const Trajectory traj = system_->cameraTrajectory();
        io::writeTrajectory(trajectory_path_, traj);
        ROS_INFO("Slam: wrote %zu poses to %s at shutdown", traj.size(), trajectory_path_.c_str());
      } catch (const std::exception& e) {
        ROS_ERROR("Slam: cannot write the trajectory at shutdown: %s", e.what());
      }
    }
    system_->shutdown();
    saveOctomapAtShutdown();
  }

 private:
  void onInit() override {
    ::ros::NodeHandle& nh = getNodeHandle();
    ::ros::NodeHandle& pnh = getPrivateNodeHandle();
    int queue_size = 100;
    pnh.param("queue_size", queue_size, 100);
    pnh.param("use_camera_info", use_camera_info_, true);
    pnh.param<std::string>("trajectory_path", trajectory_path_, "");
    pnh.param<std::string>("map_file", map_file_, "");
    pnh.param("localization_mode", localization_only_, false);
    pending_map_ = map_file_;
    pnh.param("min_rate_hz", min_rate_hz_, kDefaultMinRateHz);
    pnh.param("max_rate_hz", max_rate_hz_, kDefaultMaxRateHz);
    pnh.param("dense_map", dense_map_, false);
    pnh.param("dense_map_publish_period", dense_period_, 2.0);
    pnh.param<std::string>("octomap_path", octomap_path_, "");
    DenseMapTopicsOptions dense_topics;
    pnh.param("grid_min_height", dense_topics.grid_min_height, DenseMapTopicsOptions::kDefaultGridMinHeight);
    pnh.param("grid_max_height", dense_topics.grid_max_height, DenseMapTopicsOptions::kDefaultGridMaxHeight);
    std::string settings_path;
    if (!configure(nh, pnh, settings_path)) return;
    advertiseOutputs(nh, pnh);
    subscribeInputs(nh, queue_size, dense_topics);
    advertiseServices(nh);
    // Stopped until the reconfigure server hands over ~map_publish_period.
    map_timer_ = nh.createWallTimer(::ros::WallDuration(1.0), [this](const ::ros::WallTimerEvent&) { publishMap(); },
                                    false, false);
    startReconfigure(pnh);
    NODELET_INFO("Slam: tf %s, settings '%s'", pose_out_->describe().c_str(), settings_path.c_str());
  }

  // The pose output, the settings and the vocabulary. False (logged) when one is bad: the nodelet
  // then stays idle.
  bool configure(::ros::NodeHandle& nh, ::ros::NodeHandle& pnh, std::string& settings_path) {
    std::string voc_path;
    pnh.param<std::string>("vocabulary", voc_path, "");
    try {
      pose_out_ = std::make_unique<PoseOutput>(nh, pnh);
      settings_ = loadSettings(pnh, &settings_path);
      if (dense_map_) settings_.set("DenseMap.enabled", "1");
      camera_.configure(baseCamera(settings_), use_camera_info_, rectifiedInput(pnh, nh.resolveName(kRgbTopic)));
      if (!voc_path.empty()) {
        Stopwatch sw;
        vocabulary_ = vocabulary::Vocabulary::load(voc_path);
        NODELET_INFO("Slam: vocabulary %s (%zu words) loaded in %.1f s", voc_path.c_str(),
                     vocabulary_->size(), sw.ms() / 1000.0);
      } else {
        NODELET_WARN("Slam: no ~vocabulary: relocalisation and loop closing are off");
      }
      return true;
    } catch (const std::exception& e) {
      NODELET_ERROR("Slam: %s. The nodelet is idle until restarted with valid parameters",
                    e.what());
      return false;
    }
  }

  void advertiseOutputs(::ros::NodeHandle& nh, ::ros::NodeHandle& pnh) {
    path_pub_ = nh.advertise<nav_msgs::Path>("yolo_slam/path", 1, true);
    cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("yolo_slam/map_points", 1, true);
    marker_pub_ = nh.advertise<visualization_msgs::MarkerArray>("yolo_slam/keyframes", 1, true);
    image_transport_ = std::make_unique<image_transport::ImageTransport>(nh);
    debug_pub_ = image_transport_->advertise("yolo_slam/debug_image", 2);
    startDiagnostics(nh, pnh);
  }

  // The keypoint frames, camera info, and the colour (and with the dense map, depth) images the
  // frames were made from; the dense map's topics, service and timer.
  void subscribeInputs(::ros::NodeHandle& nh, int queue_size, const DenseMapTopicsOptions& dense_topics) {
    // Multi-threaded handle: camera_info is stored even while a frame is being processed.
    info_sub_ = getMTNodeHandle().subscribe("camera/rgb/camera_info", 10, &SlamNodelet::onInfo, this);
    // Colour and depth wait in stamp-indexed caches for the keypoint frame made from them.
    rgb_sub_.subscribe(nh, kRgbTopic, kImageQueue);
    rgb_cache_.connectInput(rgb_sub_);
    if (dense_map_) {
      depth_sub_.subscribe(nh, kDepthTopic, kImageQueue);
      depth_cache_.connectInput(depth_sub_);
      dense_pub_.advertise(nh, dense_topics);
      save_octomap_srv_ = nh.advertiseService("yolo_slam/save_octomap", &SlamNodelet::onSaveOctomap, this);
      if (dense_period_ > 0)
        dense_timer_ = nh.createWallTimer(::ros::WallDuration(dense_period_),
                                          [this](const ::ros::WallTimerEvent&) { publishDenseMap(); });
    }
    frame_sub_ = nh.subscribe("yolo_slam/keypoint_frame", queue_size, &SlamNodelet::onFrame, this,
                              ::ros::TransportHints().tcpNoDelay());
  }

  void advertiseServices(::ros::NodeHandle& nh) {
    reset_srv_ = nh.advertiseService("yolo_slam/reset", &SlamNodelet::onReset, this);
    save_srv_ = nh.advertiseService("yolo_slam/save_trajectory", &SlamNodelet::onSave, this);
    loc_srv_ = nh.advertiseService("yolo_slam/set_localization_mode", &SlamNodelet::onLocalization,
                                   this);
    save_map_srv_ = nh.advertiseService("yolo_slam/save_map", &SlamNodelet::onSaveMap, this);
    load_map_srv_ = nh.advertiseService("yolo_slam/load_map", &SlamNodelet::onLoadMap, this);
  }

  void onInfo(const sensor_msgs::CameraInfoConstPtr& info) {
    try {
      camera_.update(*info, info_sub_.getTopic());
    } catch (const std::exception& e) {
      NODELET_ERROR_THROTTLE(5.0, "Slam: %s", e.what());
    }
  }

  // The cached image with exactly this stamp (null when it is gone or never came).
  static sensor_msgs::ImageConstPtr findByStamp(message_filters::Cache<sensor_msgs::Image>& cache,
                                                const ::ros::Time& stamp) {
    const auto found = cache.getInterval(stamp, stamp);
    return found.empty() ? nullptr : found.back();
  }

  // A new keyframe's colour, depth and boxes to the dense map. Caller holds system_mutex_,
  // right after the trackFeatures that made the keyframe. A missing image skips the keyframe.
  void handDenseKeyFrame(const KeypointFrame& msg, const slam::TrackResult& res) {
    const sensor_msgs::ImageConstPtr rgb = findByStamp(rgb_cache_, msg.header.stamp);
    const sensor_msgs::ImageConstPtr depth = findByStamp(depth_cache_, msg.depth_stamp);
    try {
      if (!depth) throw Error("its depth image is no longer buffered");
      const cv::Mat bgr = rgb ? imageToBgr(*rgb, rgb_sub_.getTopic()) : cv::Mat();
      cv::Mat image;
      if (!bgr.empty() && camera().rgb_order) cv::cvtColor(bgr, image, cv::COLOR_BGR2RGB);
      else image = bgr;
      system_->addDenseKeyFrame(res, image, depthToMetres(*depth, depth_sub_.getTopic()), boxesFromMsg(msg.boxes));
    } catch (const std::exception& e) {
      NODELET_WARN_THROTTLE(5.0, "Slam: keyframe at %.3f left out of the dense map: %s", msg.header.stamp.toSec(),
                            e.what());
    }
  }

  CameraModel camera() { return camera_.get(info_sub_.getTopic()); }

  // A frame not newer than the last one tracked would be written out of order into the
  // trajectory: dropped and counted. A bag played again needs yolo_slam/reset.
  bool inStampOrder(double stamp) {
    const double last = last_stamp_.load();
    if (stamp > last) {
      last_stamp_.store(stamp);
      return true;
    }
    ++out_of_order_;
    NODELET_WARN_THROTTLE(kWarnPeriodS, "Slam: frame %.6f is not newer than the last one (%.6f): dropped, %zu "
                          "out-of-order frame(s) so far; call yolo_slam/reset when a bag restarts",
                          stamp, last, out_of_order_.load());
    return false;
  }

  void onFrame(const KeypointFrame::ConstPtr& msg) {
    if (last_index_ != 0 && msg->index > last_index_ + 1) {
      const size_t gap = msg->index - last_index_ - 1;
      dropped_ += gap;
      NODELET_WARN_THROTTLE(kWarnPeriodS, "Slam: %zu keypoint frame(s) dropped before %.3f (%zu in total); "
                            "raise ~queue_size or play the bag slower", gap, msg->header.stamp.toSec(),
                            dropped_.load());
    }
    last_index_ = msg->index;
    ++received_;
    if (!inStampOrder(msg->header.stamp.toSec())) return;
    slam::TrackResult res;
    size_t corrections = 0;
    features::FeatureFrame frame;
    if (!pose_out_->ready(msg->header.frame_id)) {
      ++rejected_;
      return;
    }
    if (camera_.awaitingFirstInfo(msg->header.stamp)) {
      ++awaiting_camera_info_;
      return;
    }
    try {
      const CameraModel cam = camera();
      Stopwatch conversion;
      frame = fromMsg(*msg, cam);
      const double conversion_ms = conversion.ms();
      if (frame.width != cam.width || frame.height != cam.height)
        throw Error("keypoint frame is " + std::to_string(frame.width) + "x" +
                    std::to_string(frame.height) + " but the calibration is " +
                    std::to_string(cam.width) + "x" + std::to_string(cam.height));
      Stopwatch sw;
      std::lock_guard<std::mutex> lock(system_mutex_);
      if (!system_) startSystem(cam);
      res = system_->trackFeatures(frame);
      corrections = system_->mapCorrections();
      recordTimes(sw.ms(), conversion_ms);
      if (dense_map_ && res.keyframe_inserted) handDenseKeyFrame(*msg, res);
    } catch (const std::exception& e) {
      ++rejected_;
      if (throttle_.shouldLog(e.what()))
        NODELET_ERROR("Slam: frame %.3f rejected: %s", msg->header.stamp.toSec(), e.what());
      return;
    }
    last_state_ = res.state;
    if (res.state == slam::TrackingState::Ok) {
      ++tracked_;
      publishPose(*msg, res, corrections);
      recordLatency(msg->header.stamp);
    } else {
      ++not_tracked_;
      NODELET_WARN_THROTTLE(kWarnPeriodS, "Slam: tracking %s at %.3f (%d inliers)", stateName(res.state),
                            msg->header.stamp.toSec(), res.inliers);
    }
    if (debug_image_ && debug_pub_.getNumSubscribers() > 0) publishDebug(*msg, res);
  }

  // Image stamp to published pose, in the ROS clock (sim time when a bag plays with --clock).
  void recordLatency(const ::ros::Time& stamp) {
    const double ms = (::ros::Time::now() - stamp).toSec() * 1000.0;
    std::lock_guard<std::mutex> lock(latency_mutex_);
    latency_ms_.push_back(ms);
    if (latency_ms_.size() > kLatencyWindow) latency_ms_.erase(latency_ms_.begin(), latency_ms_.begin() + kLatencyWindow / 2);
  }

  void publishPose(const KeypointFrame& msg, const slam::TrackResult& res, size_t corrections) {
    const geometry_msgs::PoseStamped ps = pose_out_->publish(msg.header.stamp, res.T_wc, res.inliers, corrections);
    pose_rate_->tick();
    std::lock_guard<std::mutex> lock(path_mutex_);
    path_.header = ps.header;
    path_.poses.push_back(ps);
    path_pub_.publish(path_);
  }

  void publishDebug(const KeypointFrame& msg, const slam::TrackResult& res) {
    const sensor_msgs::ImageConstPtr rgb = findByStamp(rgb_cache_, msg.header.stamp);
    cv::Mat img;
    try {
      if (rgb) img = imageToBgr(*rgb, rgb_sub_.getTopic());
    } catch (const std::exception&) {
      // The colour image was already reported by the Screening nodelet; draw on grey instead.
    }
    img = drawDebugImage(img, msg, stateName(res.state), res.inliers);
    debug_pub_.publish(cv_bridge::CvImage(msg.header, sensor_msgs::image_encodings::BGR8, img).toImageMsg());
  }

  void publishMap() {
    slam::MapSnapshot snap;
    Trajectory traj;
    {
      std::lock_guard<std::mutex> lock(system_mutex_);
      if (!system_) return;
      snap = system_->mapSnapshot();
      traj = system_->cameraTrajectory();
    }
    const ::ros::Time now = ::ros::Time::now();
    // Path rebuilt from the optimised trajectory (local BA and loop closing move old poses).
    if (!traj.empty()) {
      std::lock_guard<std::mutex> lock(path_mutex_);
      path_.header.frame_id = pose_out_->mapFrame();
      path_.header.stamp = ::ros::Time(traj.back().stamp);
      path_.poses.clear();
      path_.poses.reserve(traj.size());
      for (const auto& sp : traj) {
        geometry_msgs::PoseStamped ps;
        ps.header.frame_id = pose_out_->mapFrame();
        ps.header.stamp = ::ros::Time(sp.stamp);
        ps.pose = poseToMsg(pose_out_->publishedPose(sp.T_wc));
        path_.poses.push_back(ps);
      }
      path_pub_.publish(path_);
    }

    cloud_pub_.publish(mapPointCloud(snap, pose_out_->worldInMap(), pose_out_->mapFrame(), now));
    marker_pub_.publish(keyframeMarkers(snap, pose_out_->worldInMap(), pose_out_->mapFrame(), now));
  }

  void publishDenseMap() {
    std::lock_guard<std::mutex> lock(system_mutex_);
    const mapping::DenseMapper* dense = system_ ? system_->denseMap() : nullptr;
    if (dense) dense_pub_.publish(*dense, pose_out_->worldInMap(), pose_out_->mapFrame(), ::ros::Time::now());
  }

  // /diagnostics through diagnostic_updater: the counters below and the pose rate, sent on a
  // wall timer so they keep coming while a bag is paused.
  void startDiagnostics(::ros::NodeHandle& nh, ::ros::NodeHandle& pnh) {
    diagnostic_updater::Updater& updater = diagnostics_.begin(nh, pnh, getName());
    updater.add("tracking", this, &SlamNodelet::fillDiagnostics);
    pose_rate_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
        diagnostic_updater::FrequencyStatusParam(&min_rate_hz_, &max_rate_hz_), "published pose rate");
    updater.add(*pose_rate_);
    diagnostics_.run(nh);
  }

  // Caller holds system_mutex_.
  void recordTimes(double track_ms, double conversion_ms) {
    for (auto& [v, ms] : {std::pair<std::vector<double>*, double>{&track_ms_, track_ms}, {&conversion_ms_, conversion_ms}}) {
      v->push_back(ms);
      if (v->size() > kTimingWindow) v->erase(v->begin(), v->begin() + kTimingWindow / 2);
    }
  }

  void fillDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& st) {
    Summary track, conversion;
    slam::LiveCounts live;
    {
      std::lock_guard<std::mutex> lock(system_mutex_);
      track = summarize(track_ms_);
      conversion = summarize(conversion_ms_);
      if (system_) live = system_->liveCounts();
    }
    Summary lat;
    {
      std::lock_guard<std::mutex> lock(latency_mutex_);
      lat = summarize(latency_ms_);
    }
    const size_t dropped = dropped_, rejected = rejected_;
    const slam::TrackingState state = last_state_;
    const bool warn = dropped + rejected + out_of_order_ > 0 || state == slam::TrackingState::Lost;
    st.summaryf(warn ? diagnostic_msgs::DiagnosticStatus::WARN : diagnostic_msgs::DiagnosticStatus::OK,
                "tracking %s, %zu dropped, %zu rejected", stateName(state), dropped, rejected);
    st.add("received", received_.load());
    st.add("tracked", tracked_.load());
    st.add("not_tracked", not_tracked_.load());
    st.add("dropped", dropped);
    st.add("rejected_bad_input", rejected);
    st.add("awaiting_camera_info", awaiting_camera_info_.load());
    st.add("out_of_order", out_of_order_.load());
    st.add("track_median_ms", track.median);
    st.add("track_p95_ms", track.p95);
    st.add("track_max_ms", track.max);
    st.add("map_lock_wait_max_ms", live.map_lock_wait_max_ms);
    st.add("message_conversion_median_ms", conversion.median);
    st.add("local_mapping_median_ms", live.local_mapping_median_ms);
    st.add("keyframes", live.keyframes);
    st.add("map_points", live.map_points);
    st.add("latency_median_ms", lat.median);
    st.add("latency_p95_ms", lat.p95);
  }

  // Live parameters (cfg/Slam.cfg). The first call comes from setCallback, with the values of
  // ~localization_mode, ~map_publish_period and ~debug_image.
  void startReconfigure(const ::ros::NodeHandle& pnh) {
    reconfigure_ = std::make_unique<ReconfigureServer>(reconfigure_mutex_, pnh);
    reconfigure_->setCallback([this](SlamConfig& c, uint32_t) { onReconfigure(c); });
  }

  // Called with reconfigure_mutex_ held (by the server).
  void onReconfigure(const SlamConfig& c) {
    config_ = c;
    debug_image_ = c.debug_image;
    if (c.map_publish_period > 0) {
      map_timer_.setPeriod(::ros::WallDuration(c.map_publish_period));
      map_timer_.start();
    } else {
      map_timer_.stop();
    }
    setLocalizationOnly(c.localization_mode);
  }

  void setLocalizationOnly(bool on) {
    std::lock_guard<std::mutex> lock(system_mutex_);
    if (on == localization_only_) return;
    localization_only_ = on;
    if (system_) system_->setLocalizationOnly(on);
    NODELET_INFO("Slam: %s", on ? "localization only: mapping paused" : "mapping resumed");
  }

  bool onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
    {
      std::lock_guard<std::mutex> lock(system_mutex_);
      if (system_) system_->reset();
    }
    last_stamp_.store(-std::numeric_limits<double>::infinity());
    {
      std::lock_guard<std::mutex> lock(path_mutex_);
      path_.poses.clear();
    }
    res.success = true;
    res.message = "map and trajectory cleared";
    NODELET_INFO("Slam: reset by service");
    return true;
  }

  bool onSave(SaveTrajectory::Request& req, SaveTrajectory::Response& res) {
    const std::string path = req.path.empty() ? trajectory_path_ : req.path;
    if (path.empty()) {
      res.success = false;
      res.message = "no path given and ~trajectory_path is empty";
      return true;
    }
    try {
      Trajectory traj;
      {
        std::lock_guard<std::mutex> lock(system_mutex_);
        if (system_) traj = system_->cameraTrajectory();
      }
      io::writeTrajectory(path, traj);
      res.success = true;
      res.poses = static_cast<uint32_t>(traj.size());
      res.message = path;
      NODELET_INFO("Slam: wrote %zu poses to %s", traj.size(), path.c_str());
    } catch (const std::exception& e) {
      res.success = false;
      res.message = e.what();
      NODELET_ERROR("Slam: save_trajectory failed: %s", e.what());
    }
    return true;
  }

  // The System needs the camera, so it starts with the first frame; the localization mode and
  // a map asked for before then (~localization_mode, ~map_file, the services) apply here.
  // Caller holds system_mutex_.
  void startSystem(const CameraModel& cam) {
    system_ = std::make_unique<slam::System>(cam, settings_, vocabulary_);
    NODELET_INFO("Slam: started (fx %.1f fy %.1f cx %.1f cy %.1f, %dx%d)", cam.fx, cam.fy, cam.cx,
                 cam.cy, cam.width, cam.height);
    if (localization_only_) system_->setLocalizationOnly(true);
    if (pending_map_.empty()) return;
    try {
      const slam::MapFileInfo info = system_->loadMap(pending_map_);
      NODELET_INFO("Slam: map %s loaded (%zu keyframes, %zu points, %.0f ms); relocalising in it",
                   pending_map_.c_str(), info.keyframes, info.map_points, info.ms);
    } catch (const std::exception& e) {
      NODELET_ERROR("Slam: %s; starting with an empty map", e.what());
    }
    pending_map_.clear();
  }

  // The request's path, else ~map_file; empty when neither is set (the response says so).
  std::string mapPath(const std::string& requested, yolo_slam::MapFile::Response& res) const {
    const std::string path = requested.empty() ? map_file_ : requested;
    if (path.empty()) {
      res.success = false;
      res.message = "no path in the request and no ~map_file parameter";
    }
    return path;
  }

  void fill(const slam::MapFileInfo& info, const std::string& path, yolo_slam::MapFile::Response& res) {
    res.success = true;
    res.message = path;
    res.keyframes = static_cast<uint32_t>(info.keyframes);
    res.map_points = static_cast<uint32_t>(info.map_points);
  }

  void fail(yolo_slam::MapFile::Response& res, const char* what, const std::exception& e) {
    res.success = false;
    res.message = e.what();
    NODELET_ERROR("Slam: %s: %s", what, e.what());
  }

  bool onSaveMap(yolo_slam::MapFile::Request& req, yolo_slam::MapFile::Response& res) {
    const std::string path = mapPath(req.path, res);
    if (path.empty()) return true;
    try {
      std::lock_guard<std::mutex> lock(system_mutex_);
      if (!system_) throw Error("no map yet: the first frame has not arrived");
      const slam::MapFileInfo info = system_->saveMap(path);
      fill(info, path, res);
      NODELET_INFO("Slam: map saved to %s (%zu keyframes, %zu points, %.0f ms)", path.c_str(), info.keyframes,
                   info.map_points, info.ms);
    } catch (const std::exception& e) {
      fail(res, "save_map failed", e);
    }
    return true;
  }

  bool onLoadMap(yolo_slam::MapFile::Request& req, yolo_slam::MapFile::Response& res) {
    const std::string path = mapPath(req.path, res);
    if (path.empty()) return true;
    std::lock_guard<std::mutex> lock(system_mutex_);
    if (!system_) {
      pending_map_ = path;
      res.success = true;
      res.message = path + ": loaded when the first frame arrives (the camera is not known yet)";
      return true;
    }
    try {
      const slam::MapFileInfo info = system_->loadMap(path);
      fill(info, path, res);
      {
        std::lock_guard<std::mutex> plock(path_mutex_);
        path_.poses.clear();
      }
      NODELET_INFO("Slam: map %s loaded (%zu keyframes, %zu points); relocalising in it", path.c_str(),
                   info.keyframes, info.map_points);
    } catch (const std::exception& e) {
      fail(res, "load_map failed, the running map is kept", e);
    }
    return true;
  }

  // yolo_slam/save_octomap (yolo_slam/MapFile: path, empty = ~octomap_path): the dense map as an
  // OctoMap .bt in the SLAM world frame; keyframes = keyframes integrated, map_points = voxels.
  bool onSaveOctomap(yolo_slam::MapFile::Request& req, yolo_slam::MapFile::Response& res) {
    const std::string path = req.path.empty() ? octomap_path_ : req.path;
    try {
      if (path.empty()) throw Error("no path in the request and no ~octomap_path parameter");
      std::lock_guard<std::mutex> lock(system_mutex_);
      const mapping::DenseMapper* dense = system_ ? system_->denseMap() : nullptr;
      if (!dense) throw Error("no dense map yet: the first frame has not arrived");
      dense->writeOctomap(path);
      const mapping::DenseMapStats st = dense->stats();
      res.success = true;
      res.message = path;
      res.keyframes = static_cast<uint32_t>(st.keyframes);
      res.map_points = static_cast<uint32_t>(st.voxels);
      NODELET_INFO("Slam: octomap saved to %s (%zu voxels)", path.c_str(), st.voxels);
    } catch (const std::exception& e) {
      fail(res, "save_octomap failed", e);
    }
    return true;
  }

  // ~octomap_path after the System's shutdown (the final poses). Caller holds system_mutex_.
  void saveOctomapAtShutdown() {
    const mapping::DenseMapper* dense = system_->denseMap();
    if (!dense || octomap_path_.empty()) return;
    try {
      dense->writeOctomap(octomap_path_);
      ROS_INFO("Slam: wrote the dense map to %s at shutdown", octomap_path_.c_str());
    } catch (const std::exception& e) {
      ROS_ERROR("Slam: cannot write the dense map at shutdown: %s", e.what());
    }
  }

  bool onLocalization(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
    setLocalizationOnly(req.data);
    SlamConfig c;
    {
      boost::recursive_mutex::scoped_lock lock(reconfigure_mutex_);
      config_.localization_mode = req.data;
      c = config_;
    }
    reconfigure_->updateConfig(c);  // rqt_reconfigure shows the service's choice
    res.success = true;
    res.message = req.data ? "localization only: mapping paused" : "mapping resumed";
    return true;
  }

  using ReconfigureServer = dynamic_reconfigure::Server<SlamConfig>;
  static constexpr double kWarnPeriodS = 2.0;  // per-frame warnings at most this often
  static constexpr double kDefaultMinRateHz = 5.0;  // pose rate diagnostics warn outside this band
  static constexpr double kDefaultMaxRateHz = 60.0;
  static constexpr uint32_t kImageQueue = 30;

  // Parameters (const after onInit).
  bool use_camera_info_ = true;
  ErrorThrottle throttle_;
  bool dense_map_ = false;
  double dense_period_ = 2.0;
  double min_rate_hz_ = kDefaultMinRateHz, max_rate_hz_ = kDefaultMaxRateHz;  // read by pose_rate_
  std::string trajectory_path_, map_file_, octomap_path_;
  Config settings_;
  std::shared_ptr<const vocabulary::Vocabulary> vocabulary_;

  CameraSource camera_;  // camera_info callback vs frame callback: locks inside

  // Guards system_, localization_only_, track_ms_ and conversion_ms_ (frame callback, map timer, services,
  // diagnostics). Lock order: system_mutex_ before path_mutex_ (never the reverse).
  std::mutex system_mutex_;
  std::unique_ptr<slam::System> system_;
  bool localization_only_ = false;
  std::string pending_map_;  // loaded when the System starts (set before the first frame)
  static constexpr size_t kTimingWindow = 1000;  // timing samples kept for diagnostics
  std::vector<double> track_ms_, conversion_ms_;

  std::mutex path_mutex_;  // guards path_ (frame callback vs map timer vs reset)
  nav_msgs::Path path_;

  // Live parameters: written by the reconfigure callback, read by the frame callback.
  std::atomic<bool> debug_image_{true};
  boost::recursive_mutex reconfigure_mutex_;  // dynamic_reconfigure's lock; also guards config_
  SlamConfig config_;
  std::unique_ptr<ReconfigureServer> reconfigure_;

  // The last kRecentImages colour and depth images by stamp; message_filters::Cache locks inside.
  static constexpr unsigned kRecentImages = 60;
  message_filters::Subscriber<sensor_msgs::Image> rgb_sub_, depth_sub_;
  message_filters::Cache<sensor_msgs::Image> rgb_cache_{kRecentImages}, depth_cache_{kRecentImages};

  // Frame callback counters (the subscription's callbacks are serialised); read by diagnostics.
  uint32_t last_index_ = 0;
  std::atomic<size_t> received_{0}, tracked_{0}, not_tracked_{0}, dropped_{0}, rejected_{0};
  std::atomic<size_t> awaiting_camera_info_{0};  // frames just before the first camera_info
  // Stamp of the last frame let through (frame callback; reset stores -inf), and the frames
  // dropped for not being newer.
  std::atomic<double> last_stamp_{-std::numeric_limits<double>::infinity()};
  std::atomic<size_t> out_of_order_{0};
  // Image stamp to pose, the last kLatencyWindow frames (frame callback vs diagnostics timer).
  static constexpr size_t kLatencyWindow = 2000;
  std::mutex latency_mutex_;  // guards latency_ms_
  std::vector<double> latency_ms_;
  std::atomic<slam::TrackingState> last_state_{slam::TrackingState::NotInitialized};

  ::ros::Subscriber frame_sub_, info_sub_;
  // Pose, odometry and tf. Used by the frame callback; the map timer reads its frames and
  // mount only once system_ exists, i.e. after the frame callback resolved the mount (the
  // mount is written once, before system_ is created under system_mutex_).
  std::unique_ptr<PoseOutput> pose_out_;
  ::ros::Publisher path_pub_, cloud_pub_, marker_pub_;
  std::unique_ptr<image_transport::ImageTransport> image_transport_;
  image_transport::Publisher debug_pub_;
  // Diagnostics: fillDiagnostics reads the counters (atomics or under their mutexes);
  // FrequencyStatus locks inside.
  NodeletDiagnostics diagnostics_;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> pose_rate_;
  ::ros::ServiceServer reset_srv_, save_srv_, loc_srv_, save_map_srv_, load_map_srv_, save_octomap_srv_;
  ::ros::WallTimer map_timer_, dense_timer_;
  DenseMapPublisher dense_pub_;
};

}  // namespace ros1
}  // namespace yolo_slam

PLUGINLIB_EXPORT_CLASS(yolo_slam::ros1::SlamNodelet, nodelet::Nodelet)
