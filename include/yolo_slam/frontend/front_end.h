#pragma once
// The frame front end: one RGB-D pair and the person boxes of a frame in, a screened
// FeatureFrame out. Depth cleaning (io::decodeDepth), ORB extraction
// (features::buildFeatureFrame) and screening (screening::ScreeningPipeline: box tracking,
// Algorithm 1, frame-to-frame evidence). The one front end of slam::System::trackRgbd (the
// offline runner) and the ROS Screening nodelet, so both screen a frame identically.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/detection/box.h"
#include "yolo_slam/features/feature_frame.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/screening/pipeline.h"
#include "yolo_slam/screening/screener.h"
#include "yolo_slam/screening/temporal.h"

#include <opencv2/core.hpp>

#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

namespace yolo_slam {
namespace frontend {

struct FrontEndStats {
  screening::ScreeningStats screening;  // Screener::screen
  screening::TemporalStats temporal;    // frame-to-frame evidence (zeros when it is off)
  double extraction_ms = 0, screening_ms = 0;
  double feature_budget = 1;  // nFeatures times this were extracted (OrbOptions::dynamic_boost_max)
};

struct FrontEndResult {
  features::FeatureFrame frame;  // keypoints, depth, and the dynamic flags screening set
  detection::Boxes boxes;        // the boxes screened: detections, then carried ones (tracked)
  FrontEndStats stats;
  // A mode with person boxes, and no detection has been made since construction or clear():
  // the frame was screened without boxes (asynchronous detection before its first result).
  bool awaiting_detection = false;
};

// A frame extracted and not yet screened (FrontEnd::extract): a caller may extract the next
// frame on another thread while this one is screened and tracked.
struct Extracted {
  features::FeatureFrame frame;  // keypoints and depth, nothing flagged dynamic yet
  cv::Mat image;                 // the caller's image and cleaned depth (shared, not copied)
  cv::Mat depth;
  size_t budget_step = 0;        // extracted with nFeatures times 1 + 0.25 * budget_step
  double extraction_ms = 0;
};

// One per camera stream: screening remembers tracked boxes and the previous frame.
class FrontEnd {
 public:
  // Validates both (throws yolo_slam::Error naming the bad value).
  FrontEnd(const features::OrbOptions& orb, const screening::ScreeningOptions& screening);

  // image: BGR/RGB per cam.rgb_order, or gray. depth_m: CV_32F metres registered to the image
  // (NaN, inf, values <= 0 and beyond cam.max_depth, DepthMaxRange, are invalid), or empty for
  // no depth. Throws yolo_slam::Error when the image is empty or of an unsupported type, or the
  // depth is of another type or size than the image. Safe to call from several threads: frames are processed one at a time.
  // detector_ran false: no detection was made for this frame (asynchronous detection).
  FrontEndResult process(const cv::Mat& image, const cv::Mat& depth_m, double stamp,
                         const detection::Boxes& boxes, const CameraModel& cam, bool detector_ran = true);
  // process() in two halves. extract() checks and cleans the depth and extracts (throws as
  // process()); it takes no lock and may run on another thread beside screen(). Its budget
  // follows the newest frame screened before it starts: extracted one frame ahead, a frame is
  // sized by the one two before it. screen() screens frames one at a time, in stream order.
  Extracted extract(const cv::Mat& image, const cv::Mat& depth_m, double stamp, const CameraModel& cam) const;
  FrontEndResult screen(Extracted ex, const detection::Boxes& boxes, const CameraModel& cam, bool detector_ran = true);
  // Forgets tracked boxes and the previous frame (a new sequence or a map reset).
  void clear();

  const features::OrbExtractor& extractor() const { return *orb_.front(); }
  const screening::Screener& screener() const { return screening_->screener(); }

 private:
  // The extractor for the next frame: when screening dropped over a quarter of the last
  // frame's keypoints, the budget that would have left nFeatures (rounded up to a step, at
  // most dynamic_boost_max); else nFeatures.
  size_t budgetStep() const;
  // Extraction with orb_[step] (depth already cleaned).
  Extracted extractWith(size_t step, const cv::Mat& image, const cv::Mat& depth, double stamp,
                        const CameraModel& cam) const;
  // Screening (under mutex_); records the dropped share.
  FrontEndResult screenExtracted(Extracted ex, const detection::Boxes& boxes, const CameraModel& cam,
                                 bool detector_ran);

  // nFeatures times 1, 1 + kBoostStep, ... up to dynamic_boost_max; const after construction
  // (thread-safe).
  std::vector<std::unique_ptr<features::OrbExtractor>> orb_;
  // Share of the last screened frame's keypoints that screening dropped (written under mutex_,
  // read without it by the next frame's extraction).
  std::atomic<float> dropped_share_{0.f};
  std::atomic<bool> fresh_{true};  // no frame since construction or clear()
  const bool needs_boxes_;          // the screening mode uses person boxes
  std::atomic<bool> seen_detection_{false};  // a frame since construction or clear() was detected
  // Guards screening_ for one frame's whole process(); taken alone.
  std::mutex mutex_;
  std::unique_ptr<screening::ScreeningPipeline> screening_;
};

}  // namespace frontend
}  // namespace yolo_slam
