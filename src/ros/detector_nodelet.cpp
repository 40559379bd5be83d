// yolo_slam/Detector: YOLO person detection on the colour image; publishes BoundingBoxes with
// the image's header so the Screening nodelet can pair boxes and images by stamp.
#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include <memory>
#include <mutex>

#include "nodelet_common.h"
#include "yolo_slam/BoundingBoxes.h"
#include "yolo_slam/DetectorConfig.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/thread_name.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/detection/async_detector.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/ros/conversions.h"

namespace yolo_slam {
namespace ros1 {

class DetectorNodelet : public nodelet::Nodelet {
 public:
  ~DetectorNodelet() override {
    if (image_spinner_) image_spinner_->stop();
  }

 private:
  using ReconfigureServer = dynamic_reconfigure::Server<DetectorConfig>;
  static constexpr double kStatsPeriodS = 10.0;
  static constexpr size_t kTimingWindow = 1000;  // detection times kept for the periodic log

  void onInit() override {
    ::ros::NodeHandle& nh = getNodeHandle();
    ::ros::NodeHandle& pnh = getPrivateNodeHandle();
    int queue_size = 30;
    pnh.param("queue_size", queue_size, 30);
    // Asynchronous detection (Detection.async): an input queue of one, so the detector always
    // takes the newest image when it is free and never works through a backlog.
    int input_queue = queue_size;
    try {
      loadOptions(pnh);
      if (async_.enabled) input_queue = 1;
    } catch (const std::exception& e) {
      NODELET_ERROR("Detector: bad settings: %s. Publishing empty boxes; fix ~settings", e.what());
      options_ok_ = false;
    }
    pub_ = nh.advertise<BoundingBoxes>("yolo_slam/boxes", queue_size);
    startReconfigure(pnh);
    NODELET_INFO("Detector: input queue %d (%s)%s", input_queue,
                 input_queue == 1 ? "newest image when free" : "every image",
                 async_.min_interval_s > 0 ? ", at most one image per Detection.asyncMinInterval" : "");
    subscribeImages(nh, input_queue);
    stats_timer_ = nh.createWallTimer(::ros::WallDuration(kStatsPeriodS),
                                      [this](const ::ros::WallTimerEvent&) { logStats(); });
    diagnostics_.begin(nh, pnh, getName()).add("detection", this, &DetectorNodelet::fillDiagnostics);
    diagnostics_.run(nh);
  }

  // Images are detected on a thread of this nodelet's own (not the manager's shared workers),
  // niced by Detection.threadNice so that the frame stream's nodelets go first on a busy CPU.
  void subscribeImages(const ::ros::NodeHandle& nh, int input_queue) {
    ::ros::NodeHandle image_nh(nh);
    image_nh.setCallbackQueue(&image_queue_);
    sub_ = image_nh.subscribe(kRgbTopic, input_queue, &DetectorNodelet::onImage, this,
                              ::ros::TransportHints().tcpNoDelay());
    image_spinner_ = std::make_unique<::ros::AsyncSpinner>(1, &image_queue_);
    image_spinner_->start();
  }

  void fillDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& st) {
    bool loaded = false;
    {
      std::lock_guard<std::mutex> lock(detector_mutex_);
      loaded = enabled_ && detector_;
    }
    std::lock_guard<std::mutex> lock(stats_mutex_);
    const Summary s = summarize(ms_);
    if (loaded)
      st.summaryf(diagnostic_msgs::DiagnosticStatus::OK, "%zu images detected", frames_);
    else
      st.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no detector (disabled or the model did not load): empty boxes");
    st.add("images", frames_);
    st.add("rejected_bad_input", rejected_);
    st.add("throttled", throttled_);
    st.add("detection_median_ms", s.median);
    st.add("detection_p95_ms", s.p95);
  }

  // Settings, then the private parameters on top. Asynchronous detection runs on
  // Detection.asyncThreads threads unless ~threads says otherwise (as the offline runner).
  void loadOptions(const ::ros::NodeHandle& pnh) {
    const Config cfg = loadSettings(pnh);
    async_ = detection::AsyncDetectionOptions::load(cfg);
    pnh.param("async_detection", async_.enabled, async_.enabled);
    options_ = detection::DetectorOptions::load(cfg);
    if (async_.enabled) options_.threads = async_.threads;
    std::string model;
    if (pnh.getParam("model", model) && !model.empty()) options_.model = model;
    int threads = 0;
    if (pnh.getParam("threads", threads)) options_.threads = threads;
    // The reconfigure server starts from the parameter server: seed it with the settings.
    if (!pnh.hasParam("conf_threshold")) pnh.setParam("conf_threshold", options_.conf_threshold);
  }

  void startReconfigure(const ::ros::NodeHandle& pnh) {
    reconfigure_ = std::make_unique<ReconfigureServer>(reconfigure_mutex_, pnh);
    reconfigure_->setCallback([this](DetectorConfig& c, uint32_t) { onReconfigure(c); });
  }

  // Runs on the private queue, also once from startReconfigure: (re)loads the model when the
  // detector is wanted and its threshold changed. A failed load leaves no detector (empty boxes).
  void onReconfigure(DetectorConfig& c) {
    const float conf = static_cast<float>(c.conf_threshold);
    std::lock_guard<std::mutex> lock(detector_mutex_);
    enabled_ = c.enabled;
    if (!enabled_ || !options_ok_ || (detector_ && conf == options_.conf_threshold)) return;
    options_.conf_threshold = conf;
    try {
      options_.validate("~conf_threshold");
      detector_ = detection::makeDetector(options_);
      NODELET_INFO("Detector: %s, confidence %.2f", detector_->description().c_str(), conf);
    } catch (const std::exception& e) {
      detector_.reset();
      // Without a detector the graph still runs (boxes stay empty, screening finds nothing).
      NODELET_ERROR("Detector: cannot load the model: %s. Publishing empty boxes; fix ~model "
                    "or ~settings (Detector.model)", e.what());
    }
  }

  // Detection.asyncMinInterval in stream time: an image this soon after the last detected one
  // is skipped (no boxes published; the Screening nodelet keeps the newest result).
  bool throttled(const ::ros::Time& stamp) {
    if (async_.min_interval_s <= 0 || last_detected_.isZero()) return false;
    return (stamp - last_detected_).toSec() < async_.min_interval_s && stamp >= last_detected_;
  }

  void onImage(const sensor_msgs::ImageConstPtr& img) {
    if (!thread_niced_) {
      nameThisThread("ys_detect");
      lowerThisThreadPriority(async_.enabled ? async_.thread_nice : 0, "Detection.threadNice");
      thread_niced_ = true;
    }
    if (throttled(img->header.stamp)) {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++throttled_;
      return;
    }
    auto out = boost::make_shared<BoundingBoxes>();
    out->header = img->header;
    try {
      const cv::Mat bgr = imageToBgr(*img, sub_.getTopic());
      std::lock_guard<std::mutex> lock(detector_mutex_);
      if (enabled_ && detector_) {
        Stopwatch sw;
        toMsg(detector_->detect(bgr), *out);
        recordTime(sw.ms());
      }
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++rejected_;
      if (throttle_.shouldLog(e.what())) NODELET_ERROR("Detector: image rejected: %s", e.what());
      return;
    }
    last_detected_ = img->header.stamp;
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++frames_;
    }
    pub_.publish(out);
  }

  void recordTime(double ms) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ms_.push_back(ms);
    if (ms_.size() > kTimingWindow) ms_.erase(ms_.begin(), ms_.begin() + kTimingWindow / 2);
  }

  void logStats() {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    if (frames_ == 0) return;
    const Summary s = summarize(ms_);
    NODELET_INFO("Detector: %zu images, %zu rejected, %zu throttled, detection median %.1f ms (p95 %.1f)",
                 frames_, rejected_, throttled_, s.median, s.p95);
  }

  // Const after onInit, except options_.conf_threshold (under detector_mutex_).
  detection::AsyncDetectionOptions async_;
  detection::DetectorOptions options_;
  bool options_ok_ = true;
  ErrorThrottle throttle_;

  // Guards detector_ and enabled_: the image callback vs the reconfigure callback.
  std::mutex detector_mutex_;
  std::unique_ptr<detection::Detector> detector_;
  bool enabled_ = true;

  ::ros::Time last_detected_;  // image callback only (its callbacks are serialised)
  boost::recursive_mutex reconfigure_mutex_;  // dynamic_reconfigure's own config lock
  std::unique_ptr<ReconfigureServer> reconfigure_;
  ::ros::CallbackQueue image_queue_;  // onImage only, served by image_spinner_'s one thread
  std::unique_ptr<::ros::AsyncSpinner> image_spinner_;
  bool thread_niced_ = false;  // onImage's thread only
  ::ros::Subscriber sub_;
  ::ros::Publisher pub_;
  ::ros::WallTimer stats_timer_;
  // /diagnostics: fillDiagnostics reads the counters under their mutexes.
  NodeletDiagnostics diagnostics_;
  std::mutex stats_mutex_;  // guards frames_, rejected_, throttled_, ms_ (image callback vs stats timer)
  size_t frames_ = 0, rejected_ = 0, throttled_ = 0;
  std::vector<double> ms_;
};

}  // namespace ros1
}  // namespace yolo_slam

PLUGINLIB_EXPORT_CLASS(yolo_slam::ros1::DetectorNodelet, nodelet::Nodelet)
