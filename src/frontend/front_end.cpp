#include "yolo_slam/frontend/front_end.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/io/depth.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace yolo_slam {
namespace frontend {

namespace {

// Budget steps: fine enough that a crowd gets what it needs, few enough to build up front.
constexpr double kBoostStep = 0.25;
// The budget grows once fewer than this share of the keypoints stayed after screening: two
// walking people cost 15-25 % of them and tracking does well on the rest, so the extra
// extraction time goes to crowds, where half of the view can be people.
constexpr double kBoostBelowKept = 0.75;

// The depth as screening and tracking read it: a cleaned CV_32F copy (invalid readings 0).
cv::Mat checkedDepth(const cv::Mat& depth_m, const cv::Mat& image, double stamp, double max_depth) {
  if (depth_m.empty()) return cv::Mat();
  if (depth_m.type() != CV_32FC1 || depth_m.size() != image.size())
    throw Error("frame " + std::to_string(stamp) + ": depth image " + std::to_string(depth_m.cols) + "x" +
                std::to_string(depth_m.rows) + " of type " + cv::typeToString(depth_m.type()) +
                " does not match the " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                " colour image (need registered CV_32FC1 metres)");
  return io::decodeDepth(depth_m, 1.0, "frame " + std::to_string(stamp), max_depth);
}

}  // namespace

FrontEnd::FrontEnd(const features::OrbOptions& orb, const screening::ScreeningOptions& screening)
    : needs_boxes_(screening::stagesFor(screening).detection),
      screening_(std::make_unique<screening::ScreeningPipeline>(screening)) {
  orb.validate();
  for (double boost = 1; boost <= orb.dynamic_boost_max + 1e-9; boost += kBoostStep) {
    features::OrbOptions o = orb;
    o.n_features = static_cast<int>(std::lround(orb.n_features * boost));
    orb_.push_back(std::make_unique<features::OrbExtractor>(o));
  }
}

size_t FrontEnd::budgetStep() const {
  const double kept = 1.0 - dropped_share_.load();
  if (kept <= 0) return orb_.size() - 1;
  if (kept >= kBoostBelowKept) return 0;
  // The budget that would have left nFeatures, rounded up to a step.
  const size_t step = static_cast<size_t>(std::ceil((1.0 / kept - 1) / kBoostStep - 1e-9));
  return std::min(step, orb_.size() - 1);
}

Extracted FrontEnd::extractWith(size_t step, const cv::Mat& image, const cv::Mat& depth, double stamp,
                                const CameraModel& cam) const {
  Extracted ex;
  Stopwatch sw;
  ex.frame = features::buildFeatureFrame(*orb_[step], cam, image, depth, stamp);
  ex.extraction_ms = sw.ms();
  ex.image = image;
  ex.depth = depth;
  ex.budget_step = step;
  return ex;
}

FrontEndResult FrontEnd::screenExtracted(Extracted ex, const detection::Boxes& boxes, const CameraModel& cam,
                                         bool detector_ran) {
  FrontEndResult r;
  r.frame = std::move(ex.frame);
  r.stats.extraction_ms = ex.extraction_ms;
  r.stats.feature_budget = 1 + kBoostStep * ex.budget_step;
  Stopwatch sw;
  screening::PipelineResult screened;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    screened = screening_->process(r.frame, boxes, cam, ex.depth, detector_ran);
    const size_t n = r.frame.size();
    dropped_share_ = n > 0 ? static_cast<float>(r.frame.countDynamic()) / n : 0.f;
  }
  r.stats.screening_ms = sw.ms();
  r.boxes = std::move(screened.boxes);
  r.stats.screening = screened.stats;
  r.stats.temporal = screened.temporal;
  return r;
}

Extracted FrontEnd::extract(const cv::Mat& image, const cv::Mat& depth_m, double stamp,
                            const CameraModel& cam) const {
  if (image.empty()) throw Error("frame " + std::to_string(stamp) + ": empty image");
  const cv::Mat depth = checkedDepth(depth_m, image, stamp, cam.max_depth);
  return extractWith(budgetStep(), image, depth, stamp, cam);
}

FrontEndResult FrontEnd::screen(Extracted ex, const detection::Boxes& boxes, const CameraModel& cam,
                                bool detector_ran) {
  const cv::Mat image = ex.image, depth = ex.depth;
  const double stamp = ex.frame.stamp;
  const size_t step = ex.budget_step;
  FrontEndResult r = screenExtracted(std::move(ex), boxes, cam, detector_ran);
  // The first frame of a stream has no last frame to size its budget by, and SLAM initialises
  // on it: when it needed more, it is extracted again (screening has seen nothing else yet).
  const size_t needed = budgetStep();
  if (fresh_.exchange(false) && needed > step) {
    const double first_ms = r.stats.extraction_ms + r.stats.screening_ms;
    clear();
    fresh_ = false;
    r = screenExtracted(extractWith(needed, image, depth, stamp, cam), boxes, cam, detector_ran);
    r.stats.extraction_ms += first_ms;
  }
  // After the re-extraction above: its clear() forgets earlier detections, not this frame's.
  if (detector_ran) seen_detection_ = true;
  r.awaiting_detection = needs_boxes_ && !seen_detection_;
  return r;
}

FrontEndResult FrontEnd::process(const cv::Mat& image, const cv::Mat& depth_m, double stamp,
                                 const detection::Boxes& boxes, const CameraModel& cam, bool detector_ran) {
  return screen(extract(image, depth_m, stamp, cam), boxes, cam, detector_ran);
}

void FrontEnd::clear() {
  std::lock_guard<std::mutex> lk(mutex_);
  screening_->clear();
  dropped_share_ = 0.f;
  fresh_ = true;
  seen_detection_ = false;
}

}  // namespace frontend
}  // namespace yolo_slam
