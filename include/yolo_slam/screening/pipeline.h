#pragma once
// Everything screening does to one frame of a camera stream, in order: carry person boxes over
// frames the detector misses (BoxTracker, Screening.trackBoxes), Algorithm 1 in every box
// (Screener), then the frame-to-frame evidence (TemporalScreening: static-box veto, motion
// screening, label propagation; Screening.staticBoxVeto, motionScreening, propagateLabels). Used by
// slam::System::trackRgbd and the ROS Screening nodelet, so the offline runner and the nodelet
// graph screen identically.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/detection/box.h"
#include "yolo_slam/features/feature_frame.h"
#include "yolo_slam/screening/box_tracker.h"
#include "yolo_slam/screening/screener.h"
#include "yolo_slam/screening/temporal.h"

#include <memory>

namespace yolo_slam {
namespace screening {

// Which stages of screening run: decided here once, from the mode and the stage switches,
// for the pipeline, the runner and the nodelets.
struct Stages {
  bool detection = false;          // person boxes are needed: modes detect and detect+geometry
  bool box_tracking = false;       // Screening.trackBoxes, in a mode with boxes
  bool label_propagation = false;  // Screening.propagateLabels, in every mode but off
  bool static_box_veto = false;    // Screening.staticBoxVeto, in every mode but off
  bool motion_screening = false;   // Screening.motionScreening, in every mode but off
  bool temporal() const { return label_propagation || static_box_veto || motion_screening; }
};
Stages stagesFor(const ScreeningOptions& options);

struct PipelineResult {
  detection::Boxes boxes;  // the boxes screened: detections, then tracked boxes (tracked = true)
  ScreeningStats stats;    // of Screener::screen
  TemporalStats temporal;  // of TemporalScreening::apply (zeros when it is off)
};

// One per camera stream. process() keeps state between frames and is not thread-safe: the
// caller serialises frames (System holds a mutex, the nodelet's synchroniser calls one at a time).
class ScreeningPipeline {
 public:
  explicit ScreeningPipeline(const ScreeningOptions& options);  // validates
  const Screener& screener() const { return screener_; }

  // Screens `frame` (sets frame.dynamic) with the detector's boxes of this frame; `cam` gives
  // the intrinsics for label propagation's camera-motion estimate; depth_m (CV_32F metres, may
  // be empty) the depth image for the silhouette rule.
  // detector_ran false: `detections` is empty because the detector did not look at this frame
  // (asynchronous detection), not because it found nobody.
  PipelineResult process(features::FeatureFrame& frame, const detection::Boxes& detections,
                         const CameraModel& cam, const cv::Mat& depth_m = cv::Mat(), bool detector_ran = true);
  // Forgets tracked boxes and the previous frame (a new sequence or a map reset).
  void clear();

 private:
  Screener screener_;
  std::unique_ptr<BoxTracker> box_tracker_;    // null unless trackBoxes in a detect mode
  // Null unless propagateLabels or staticBoxVeto, in a mode other than off.
  std::unique_ptr<TemporalScreening> temporal_;
};

}  // namespace screening
}  // namespace yolo_slam
