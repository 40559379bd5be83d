#include "yolo_slam/frontend/front_end.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/io/depth.h"

#include <string>

namespace yolo_slam {
namespace frontend {

namespace {

// The depth as screening and tracking read it: a cleaned CV_32F copy (invalid readings 0).
cv::Mat checkedDepth(const cv::Mat& depth_m, const cv::Mat& image, double stamp) {
  if (depth_m.empty()) return cv::Mat();
  if (depth_m.type() != CV_32FC1 || depth_m.size() != image.size())
    throw Error("frame " + std::to_string(stamp) + ": depth image " + std::to_string(depth_m.cols) + "x" +
                std::to_string(depth_m.rows) + " of type " + cv::typeToString(depth_m.type()) +
                " does not match the " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                " colour image (need registered CV_32FC1 metres)");
  return io::decodeDepth(depth_m, 1.0, "frame " + std::to_string(stamp));
}

}  // namespace

FrontEnd::FrontEnd(const features::OrbOptions& orb, const screening::ScreeningOptions& screening)
    : orb_(std::make_unique<features::OrbExtractor>(orb)),
      screening_(std::make_unique<screening::ScreeningPipeline>(screening)) {}

FrontEndResult FrontEnd::process(const cv::Mat& image, const cv::Mat& depth_m, double stamp,
                                 const detection::Boxes& boxes, const CameraModel& cam, bool detector_ran) {
  if (image.empty()) throw Error("frame " + std::to_string(stamp) + ": empty image");
  const cv::Mat depth = checkedDepth(depth_m, image, stamp);
  FrontEndResult r;
  Stopwatch sw;
  r.frame = features::buildFeatureFrame(*orb_, cam, image, depth, stamp);
  r.stats.extraction_ms = sw.ms();
  sw.restart();
  screening::PipelineResult screened;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    screened = screening_->process(r.frame, boxes, cam, depth, detector_ran);
  }
  r.stats.screening_ms = sw.ms();
  r.boxes = std::move(screened.boxes);
  r.stats.screening = screened.stats;
  r.stats.temporal = screened.temporal;
  return r;
}

void FrontEnd::clear() {
  std::lock_guard<std::mutex> lk(mutex_);
  screening_->clear();
}

}  // namespace frontend
}  // namespace yolo_slam
