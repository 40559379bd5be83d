#include "yolo_slam/screening/pipeline.h"

namespace yolo_slam {
namespace screening {

ScreeningPipeline::ScreeningPipeline(const ScreeningOptions& options) : screener_(options) {
  const DynamicMode m = options.mode;
  if (options.track_boxes && (m == DynamicMode::Detect || m == DynamicMode::DetectGeometry))
    box_tracker_ = std::make_unique<BoxTracker>(BoxTrackerOptions::from(options));
  const TemporalOptions topt = TemporalOptions::from(options);
  if (topt.enabled() && m != DynamicMode::Off) temporal_ = std::make_unique<TemporalScreening>(topt);
}

PipelineResult ScreeningPipeline::process(features::FeatureFrame& frame,
                                          const detection::Boxes& detections,
                                          const CameraModel& cam, const cv::Mat& depth_m) {
  PipelineResult r;
  r.boxes = box_tracker_ ? box_tracker_->predict(frame, detections) : detections;
  r.stats = screener_.screen(frame, r.boxes, depth_m);
  // The tracker remembers what screening found in its boxes, before propagation adds labels
  // that may lie outside them and the veto removes some.
  if (box_tracker_) box_tracker_->observe(frame);
  if (temporal_) r.temporal = temporal_->apply(frame, r.boxes, cam);
  return r;
}

void ScreeningPipeline::clear() {
  if (box_tracker_) box_tracker_->clear();
  if (temporal_) temporal_->clear();
}

}  // namespace screening
}  // namespace yolo_slam
