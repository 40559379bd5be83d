// yolo_slam/Detector: YOLO person detection on the colour image; publishes BoundingBoxes with
// the image's header so the Screening nodelet can pair boxes and images by stamp.
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include <memory>
#include <mutex>

#include "nodelet_common.h"
#include "yolo_slam/detection/async_detector.h"
#include "yolo_slam/BoundingBoxes.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/ros/conversions.h"

namespace yolo_slam {
namespace ros1 {

class DetectorNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ::ros::NodeHandle& nh = getNodeHandle();
    ::ros::NodeHandle& pnh = getPrivateNodeHandle();
    int queue_size = 30;
    pnh.param("queue_size", queue_size, 30);
    pnh.param("enabled", enabled_, true);
    std::string model;
    pnh.param<std::string>("model", model, "");
    // Asynchronous detection (Detection.async): an input queue of one, so the detector always
    // takes the newest image when it is free and never works through a backlog.
    int input_queue = queue_size;
    if (enabled_) {
      try {
        const Config cfg = loadSettings(pnh);
        bool async = detection::AsyncDetectionOptions::load(cfg).enabled;
        pnh.param("async_detection", async, async);
        if (async) input_queue = 1;
        detection::DetectorOptions opt = detection::DetectorOptions::load(cfg);
        if (!model.empty()) opt.model = model;
        double conf = -1;
        if (pnh.getParam("conf_threshold", conf)) opt.conf_threshold = static_cast<float>(conf);
        int threads = 0;
        if (pnh.getParam("threads", threads)) opt.threads = threads;
        detector_ = detection::makeDetector(opt);
        NODELET_INFO("Detector: %s; input queue %d (%s)", detector_->description().c_str(), input_queue,
                     input_queue == 1 ? "newest image when free" : "every image");
      } catch (const std::exception& e) {
        // Without a detector the graph still runs (boxes stay empty, screening finds nothing).
        NODELET_ERROR("Detector: cannot load the model: %s. Publishing empty boxes; fix ~model "
                      "or ~settings (Detector.model)", e.what());
      }
    }
    pub_ = nh.advertise<BoundingBoxes>("yolo_slam/boxes", queue_size);
    sub_ = nh.subscribe("camera/rgb/image_color", input_queue, &DetectorNodelet::onImage, this,
                        ::ros::TransportHints().tcpNoDelay());
    stats_timer_ = nh.createWallTimer(::ros::WallDuration(10.0), [this](const ::ros::WallTimerEvent&) {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      if (frames_ == 0) return;
      const Summary s = summarize(ms_);
      NODELET_INFO("Detector: %zu images, %zu rejected, detection median %.1f ms (p95 %.1f)",
                   frames_, rejected_, s.median, s.p95);
    });
  }

  void onImage(const sensor_msgs::ImageConstPtr& img) {
    auto out = boost::make_shared<BoundingBoxes>();
    out->header = img->header;
    try {
      cv::Mat bgr = imageToBgr(*img, sub_.getTopic());
      if (detector_) {
        Stopwatch sw;
        toMsg(detector_->detect(bgr), *out);
        std::lock_guard<std::mutex> lock(stats_mutex_);
        ms_.push_back(sw.ms());
        if (ms_.size() > 1000) ms_.erase(ms_.begin(), ms_.begin() + 500);
      }
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++rejected_;
      if (throttle_.shouldLog(e.what())) NODELET_ERROR("Detector: image rejected: %s", e.what());
      return;
    }
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++frames_;
    }
    pub_.publish(out);
  }

  bool enabled_ = true;
  ErrorThrottle throttle_;
  std::unique_ptr<detection::Detector> detector_;  // used by the image callback only
  ::ros::Subscriber sub_;
  ::ros::Publisher pub_;
  ::ros::WallTimer stats_timer_;
  std::mutex stats_mutex_;  // guards frames_, rejected_, ms_ (image callback vs stats timer)
  size_t frames_ = 0, rejected_ = 0;
  std::vector<double> ms_;
};

}  // namespace ros1
}  // namespace yolo_slam

PLUGINLIB_EXPORT_CLASS(yolo_slam::ros1::DetectorNodelet, nodelet::Nodelet)
