// yolo_slam/Slam: tracking + mapping on the screened keypoint frames. Pose, odometry and tf follow
// REP 103 / REP 105 (pose_output.h); also the path, the static map points, keyframes with
// covisibility edges and a debug image; services reset, save_trajectory (TUM format),
// set_localization_mode, save_map and load_map (map files).
#include <cv_bridge/cv_bridge.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Path.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>
#include <opencv2/imgproc.hpp>

#include <atomic>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>

#include "dense_map_publisher.h"
#include "nodelet_common.h"
#include "pose_output.h"
#include "yolo_slam/KeypointFrame.h"
#include "yolo_slam/MapFile.h"
#include "yolo_slam/SaveTrajectory.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/detection/draw.h"
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
    diag_timer_.stop();
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
    pnh.param("map_publish_period", map_period_, 1.0);
    pnh.param("debug_image", debug_image_, true);
    pnh.param("dense_map", dense_map_, false);
    pnh.param("dense_map_publish_period", dense_period_, 2.0);
    pnh.param<std::string>("octomap_path", octomap_path_, "");
    DenseMapTopicsOptions dense_topics;
    pnh.param("grid_min_height", dense_topics.grid_min_height, DenseMapTopicsOptions::kDefaultGridMinHeight);
    pnh.param("grid_max_height", dense_topics.grid_max_height, DenseMapTopicsOptions::kDefaultGridMaxHeight);
    std::string settings_path, voc_path;
    pnh.param<std::string>("vocabulary", voc_path, "");
    try {
      pose_out_ = std::make_unique<PoseOutput>(nh, pnh);
      settings_ = loadSettings(pnh, &settings_path);
      if (dense_map_) settings_.set("DenseMap.enabled", "1");
      camera_.configure(baseCamera(settings_), use_camera_info_);
      if (!voc_path.empty()) {
        Stopwatch sw;
        vocabulary_ = vocabulary::Vocabulary::load(voc_path);
        NODELET_INFO("Slam: vocabulary %s (%zu words) loaded in %.1f s", voc_path.c_str(),
                     vocabulary_->size(), sw.ms() / 1000.0);
      } else {
        NODELET_WARN("Slam: no ~vocabulary: relocalisation and loop closing are off");
      }
    } catch (const std::exception& e) {
      NODELET_ERROR("Slam: %s. The nodelet is idle until restarted with valid parameters",
                    e.what());
      return;
    }

    path_pub_ = nh.advertise<nav_msgs::Path>("yolo_slam/path", 1, true);
    cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("yolo_slam/map_points", 1, true);
    marker_pub_ = nh.advertise<visualization_msgs::MarkerArray>("yolo_slam/keyframes", 1, true);
    debug_pub_ = nh.advertise<sensor_msgs::Image>("yolo_slam/debug_image", 2);
    diag_pub_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 10);
    // Multi-threaded handle: camera_info is stored even while a frame is being processed.
    info_sub_ = getMTNodeHandle().subscribe("camera/rgb/camera_info", 10, &SlamNodelet::onInfo, this);
    if (debug_image_ || dense_map_)
      rgb_sub_ = nh.subscribe("camera/rgb/image_color", 30, &SlamNodelet::onRgb, this);
    if (dense_map_) {
      depth_sub_ = nh.subscribe("camera/depth/image", 30, &SlamNodelet::onDepth, this);
      dense_pub_.advertise(nh, dense_topics);
      save_octomap_srv_ = nh.advertiseService("yolo_slam/save_octomap", &SlamNodelet::onSaveOctomap, this);
      if (dense_period_ > 0)
        dense_timer_ = nh.createWallTimer(::ros::WallDuration(dense_period_),
                                          [this](const ::ros::WallTimerEvent&) { publishDenseMap(); });
    }
    frame_sub_ = nh.subscribe("yolo_slam/keypoint_frame", queue_size, &SlamNodelet::onFrame, this,
                              ::ros::TransportHints().tcpNoDelay());
    reset_srv_ = nh.advertiseService("yolo_slam/reset", &SlamNodelet::onReset, this);
    save_srv_ = nh.advertiseService("yolo_slam/save_trajectory", &SlamNodelet::onSave, this);
    loc_srv_ = nh.advertiseService("yolo_slam/set_localization_mode", &SlamNodelet::onLocalization,
                                   this);
    save_map_srv_ = nh.advertiseService("yolo_slam/save_map", &SlamNodelet::onSaveMap, this);
    load_map_srv_ = nh.advertiseService("yolo_slam/load_map", &SlamNodelet::onLoadMap, this);
    if (map_period_ > 0)
      map_timer_ = nh.createWallTimer(::ros::WallDuration(map_period_),
                                      [this](const ::ros::WallTimerEvent&) { publishMap(); });
    diag_timer_ = nh.createWallTimer(::ros::WallDuration(1.0),
                                     [this](const ::ros::WallTimerEvent&) { publishDiagnostics(); });
    NODELET_INFO("Slam: tf %s, settings '%s'", pose_out_->describe().c_str(), settings_path.c_str());
  }

  void onInfo(const sensor_msgs::CameraInfoConstPtr& info) {
    try {
      camera_.update(*info, info_sub_.getTopic());
    } catch (const std::exception& e) {
      NODELET_ERROR_THROTTLE(5.0, "Slam: %s", e.what());
    }
  }

  void onRgb(const sensor_msgs::ImageConstPtr& img) {
    std::lock_guard<std::mutex> lock(rgb_mutex_);
    recent_rgb_.push_back(img);
    while (recent_rgb_.size() > kRecentImages) recent_rgb_.pop_front();
  }

  void onDepth(const sensor_msgs::ImageConstPtr& img) {
    std::lock_guard<std::mutex> lock(rgb_mutex_);
    recent_depth_.push_back(img);
    while (recent_depth_.size() > kRecentImages) recent_depth_.pop_front();
  }

  // The newest of `images` with this stamp (null if gone). Caller holds rgb_mutex_.
  static sensor_msgs::ImageConstPtr findByStamp(const std::deque<sensor_msgs::ImageConstPtr>& images,
                                                const ::ros::Time& stamp) {
    for (auto it = images.rbegin(); it != images.rend(); ++it)
      if ((*it)->header.stamp == stamp) return *it;
    return nullptr;
  }

  // A new keyframe's colour, depth and boxes to the dense map. Caller holds system_mutex_,
  // right after the trackFeatures that made the keyframe. A missing image skips the keyframe.
  void handDenseKeyFrame(const KeypointFrame& msg, const slam::TrackResult& res) {
    sensor_msgs::ImageConstPtr rgb, depth;
    {
      std::lock_guard<std::mutex> lock(rgb_mutex_);
      rgb = findByStamp(recent_rgb_, msg.header.stamp);
      depth = findByStamp(recent_depth_, msg.depth_stamp);
    }
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
    NODELET_WARN_THROTTLE(2.0, "Slam: frame %.6f is not newer than the last one (%.6f): dropped, %zu "
                          "out-of-order frame(s) so far; call yolo_slam/reset when a bag restarts",
                          stamp, last, out_of_order_.load());
    return false;
  }

  void onFrame(const KeypointFrame::ConstPtr& msg) {
    if (last_index_ != 0 && msg->index > last_index_ + 1) {
      const size_t gap = msg->index - last_index_ - 1;
      dropped_ += gap;
      NODELET_WARN("Slam: %zu keypoint frame(s) dropped before %.3f (%zu in total); raise "
                   "~queue_size or play the bag slower", gap, msg->header.stamp.toSec(),
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
    try {
      const CameraModel cam = camera();
      frame = fromMsg(*msg, cam);
      if (frame.width != cam.width || frame.height != cam.height)
        throw Error("keypoint frame is " + std::to_string(frame.width) + "x" +
                    std::to_string(frame.height) + " but the calibration is " +
                    std::to_string(cam.width) + "x" + std::to_string(cam.height));
      Stopwatch sw;
      std::lock_guard<std::mutex> lock(system_mutex_);
      if (!system_) startSystem(cam);
      res = system_->trackFeatures(frame);
      corrections = system_->mapCorrections();
      track_ms_.push_back(sw.ms());
      if (dense_map_ && res.keyframe_inserted) handDenseKeyFrame(*msg, res);
      if (track_ms_.size() > 1000) track_ms_.erase(track_ms_.begin(), track_ms_.begin() + 500);
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
      NODELET_WARN_THROTTLE(2.0, "Slam: tracking %s at %.3f (%d inliers)", stateName(res.state),
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
    std::lock_guard<std::mutex> lock(path_mutex_);
    path_.header = ps.header;
    path_.poses.push_back(ps);
    path_pub_.publish(path_);
  }

  void publishDebug(const KeypointFrame& msg, const slam::TrackResult& res) {
    sensor_msgs::ImageConstPtr rgb;
    {
      std::lock_guard<std::mutex> lock(rgb_mutex_);
      for (auto it = recent_rgb_.rbegin(); it != recent_rgb_.rend(); ++it)
        if ((*it)->header.stamp == msg.header.stamp) {
          rgb = *it;
          break;
        }
    }
    cv::Mat img;
    try {
      if (rgb) img = imageToBgr(*rgb, rgb_sub_.getTopic());
    } catch (const std::exception&) {
      // The colour image was already reported by the Screening nodelet; draw on grey instead.
    }
    if (img.empty()) img = cv::Mat(msg.height, msg.width, CV_8UC3, cv::Scalar(64, 64, 64));
    detection::drawBoxes(img, boxesFromMsg(msg.boxes));
    int kept = 0, dropped = 0;
    for (size_t i = 0; i < msg.keypoints.size(); ++i) {
      const bool dyn = msg.dynamic[i] != 0;
      (dyn ? dropped : kept)++;
      const cv::Point p(cvRound(msg.keypoints[i].x), cvRound(msg.keypoints[i].y));
      if (dyn)
        cv::drawMarker(img, p, cv::Scalar(0, 0, 255), cv::MARKER_TILTED_CROSS, 7, 1);
      else
        cv::circle(img, p, 3, cv::Scalar(0, 255, 0), 1);
    }
    const std::string text = std::string("tracking ") + stateName(res.state) + "  kept " +
                             std::to_string(kept) + "  dropped " + std::to_string(dropped) +
                             "  inliers " + std::to_string(res.inliers);
    cv::putText(img, text, cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 3);
    cv::putText(img, text, cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5,
                cv::Scalar(255, 255, 255), 1);
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

    auto cloud = boost::make_shared<sensor_msgs::PointCloud2>();
    const Pose T_map_world = pose_out_->worldInMap();
    cloud->header.frame_id = pose_out_->mapFrame();
    cloud->header.stamp = now;
    sensor_msgs::PointCloud2Modifier mod(*cloud);
    mod.setPointCloud2FieldsByString(1, "xyz");
    mod.resize(snap.points.size());
    sensor_msgs::PointCloud2Iterator<float> x(*cloud, "x"), y(*cloud, "y"), z(*cloud, "z");
    for (const auto& p : snap.points) {
      const Eigen::Vector3d q = T_map_world * p;
      *x = static_cast<float>(q.x());
      *y = static_cast<float>(q.y());
      *z = static_cast<float>(q.z());
      ++x, ++y, ++z;
    }
    cloud_pub_.publish(cloud);

    auto markers = boost::make_shared<visualization_msgs::MarkerArray>();
    visualization_msgs::Marker kf, edges;
    kf.header.frame_id = edges.header.frame_id = pose_out_->mapFrame();
    kf.header.stamp = edges.header.stamp = now;
    kf.ns = "keyframes";
    edges.ns = "covisibility";
    kf.type = edges.type = visualization_msgs::Marker::LINE_LIST;
    kf.action = edges.action = visualization_msgs::Marker::ADD;
    kf.pose.orientation.w = edges.pose.orientation.w = 1.0;
    kf.scale.x = 0.005;
    edges.scale.x = 0.002;
    kf.color.b = 1.0f;
    kf.color.a = 1.0f;
    edges.color.g = 0.8f;
    edges.color.a = 0.6f;
    auto pt = [](const Eigen::Vector3d& v) {
      geometry_msgs::Point p;
      p.x = v.x();
      p.y = v.y();
      p.z = v.z();
      return p;
    };
    // A small camera frustum per keyframe (apex + 4 image corners at 5 cm).
    const double w = 0.04, h = 0.03, d = 0.05;
    const Eigen::Vector3d corners[4] = {{-w, -h, d}, {w, -h, d}, {w, h, d}, {-w, h, d}};
    std::vector<Eigen::Vector3d> centres;
    for (const auto& k : snap.keyframes) {
      const Pose T = T_map_world * k.T_wc;
      const Eigen::Vector3d o = T.translation();
      centres.push_back(o);
      for (int i = 0; i < 4; ++i) {
        kf.points.push_back(pt(o));
        kf.points.push_back(pt(T * corners[i]));
        kf.points.push_back(pt(T * corners[i]));
        kf.points.push_back(pt(T * corners[(i + 1) % 4]));
      }
    }
    for (const auto& e : snap.covisibility_edges) {
      if (e.first < 0 || e.second < 0 || e.first >= static_cast<int>(centres.size()) ||
          e.second >= static_cast<int>(centres.size()))
        continue;
      edges.points.push_back(pt(centres[e.first]));
      edges.points.push_back(pt(centres[e.second]));
    }
    if (kf.points.empty()) kf.action = visualization_msgs::Marker::DELETE;
    if (edges.points.empty()) edges.action = visualization_msgs::Marker::DELETE;
    markers->markers.push_back(kf);
    markers->markers.push_back(edges);
    marker_pub_.publish(markers);
  }

  void publishDenseMap() {
    std::lock_guard<std::mutex> lock(system_mutex_);
    const mapping::DenseMapper* dense = system_ ? system_->denseMap() : nullptr;
    if (dense) dense_pub_.publish(*dense, pose_out_->worldInMap(), pose_out_->mapFrame(), ::ros::Time::now());
  }

  void publishDiagnostics() {
    diagnostic_msgs::DiagnosticStatus st;
    st.name = getName() + ": tracking";
    st.hardware_id = "yolo_slam";
    Summary s;
    {
      std::lock_guard<std::mutex> lock(system_mutex_);
      s = summarize(track_ms_);
    }
    const size_t dropped = dropped_, rejected = rejected_;
    const slam::TrackingState state = last_state_;
    st.level = dropped + rejected + out_of_order_ > 0 || state == slam::TrackingState::Lost
                   ? diagnostic_msgs::DiagnosticStatus::WARN
                   : diagnostic_msgs::DiagnosticStatus::OK;
    st.message = std::string("tracking ") + stateName(state) + ", " + std::to_string(dropped) +
                 " dropped, " + std::to_string(rejected) + " rejected";
    auto kv = [&](const std::string& k, size_t v) {
      diagnostic_msgs::KeyValue p;
      p.key = k;
      p.value = std::to_string(v);
      st.values.push_back(p);
    };
    kv("received", received_);
    kv("tracked", tracked_);
    kv("not_tracked", not_tracked_);
    kv("dropped", dropped);
    kv("rejected_bad_input", rejected);
    kv("out_of_order", out_of_order_);
    diagnostic_msgs::KeyValue m;
    m.key = "track_median_ms";
    m.value = std::to_string(s.median);
    st.values.push_back(m);
    Summary lat;
    {
      std::lock_guard<std::mutex> lock(latency_mutex_);
      lat = summarize(latency_ms_);
    }
    for (const auto& kvp : {std::make_pair("latency_median_ms", lat.median), std::make_pair("latency_p95_ms", lat.p95)}) {
      diagnostic_msgs::KeyValue l;
      l.key = kvp.first;
      l.value = std::to_string(kvp.second);
      st.values.push_back(l);
    }
    diagnostic_msgs::DiagnosticArray arr;
    arr.header.stamp = ::ros::Time::now();
    arr.status.push_back(st);
    diag_pub_.publish(arr);
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
    std::lock_guard<std::mutex> lock(system_mutex_);
    localization_only_ = req.data;
    if (system_) system_->setLocalizationOnly(req.data);
    res.success = true;
    res.message = req.data ? "localization only: mapping paused" : "mapping resumed";
    NODELET_INFO("Slam: %s", res.message.c_str());
    return true;
  }

  // Parameters (const after onInit).
  bool use_camera_info_ = true;
  ErrorThrottle throttle_;
  bool debug_image_ = true, dense_map_ = false;
  double map_period_ = 1.0, dense_period_ = 2.0;
  std::string trajectory_path_, map_file_, octomap_path_;
  Config settings_;
  std::shared_ptr<const vocabulary::Vocabulary> vocabulary_;

  CameraSource camera_;  // camera_info callback vs frame callback: locks inside

  // Guards system_, localization_only_ and track_ms_ (frame callback, map timer, services,
  // diagnostics). Lock order: system_mutex_ before path_mutex_ (never the reverse).
  std::mutex system_mutex_;
  std::unique_ptr<slam::System> system_;
  bool localization_only_ = false;
  std::string pending_map_;  // loaded when the System starts (set before the first frame)
  std::vector<double> track_ms_;

  std::mutex path_mutex_;  // guards path_ (frame callback vs map timer vs reset)
  nav_msgs::Path path_;

  // Guards recent_rgb_ and recent_depth_ (image callbacks vs frame callback); taken alone or
  // after system_mutex_.
  static constexpr size_t kRecentImages = 60;
  std::mutex rgb_mutex_;
  std::deque<sensor_msgs::ImageConstPtr> recent_rgb_, recent_depth_;

  // Frame callback counters (the subscription's callbacks are serialised); read by diagnostics.
  uint32_t last_index_ = 0;
  std::atomic<size_t> received_{0}, tracked_{0}, not_tracked_{0}, dropped_{0}, rejected_{0};
  // Stamp of the last frame let through (frame callback; reset stores -inf), and the frames
  // dropped for not being newer.
  std::atomic<double> last_stamp_{-std::numeric_limits<double>::infinity()};
  std::atomic<size_t> out_of_order_{0};
  // Image stamp to pose, the last kLatencyWindow frames (frame callback vs diagnostics timer).
  static constexpr size_t kLatencyWindow = 2000;
  std::mutex latency_mutex_;  // guards latency_ms_
  std::vector<double> latency_ms_;
  std::atomic<slam::TrackingState> last_state_{slam::TrackingState::NotInitialized};

  ::ros::Subscriber frame_sub_, info_sub_, rgb_sub_, depth_sub_;
  // Pose, odometry and tf. Used by the frame callback; the map timer reads its frames and
  // mount only once system_ exists, i.e. after the frame callback resolved the mount (the
  // mount is written once, before system_ is created under system_mutex_).
  std::unique_ptr<PoseOutput> pose_out_;
  ::ros::Publisher path_pub_, cloud_pub_, marker_pub_, debug_pub_, diag_pub_;
  ::ros::ServiceServer reset_srv_, save_srv_, loc_srv_, save_map_srv_, load_map_srv_, save_octomap_srv_;
  ::ros::WallTimer map_timer_, diag_timer_, dense_timer_;
  DenseMapPublisher dense_pub_;
};

}  // namespace ros1
}  // namespace yolo_slam

PLUGINLIB_EXPORT_CLASS(yolo_slam::ros1::SlamNodelet, nodelet::Nodelet)
