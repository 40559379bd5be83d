#include "yolo_slam/screening/pipeline.h"

namespace yolo_slam {
namespace screening {

Stages stagesFor(const ScreeningOptions& o) {
  Stages s;
  s.detection = o.mode == DynamicMode::Detect || o.mode == DynamicMode::DetectGeometry;
  s.box_tracking = s.detection && o.tracker.enabled;
  const bool screens = o.mode != DynamicMode::Off;
  s.label_propagation = screens && o.temporal.propagate_labels;
  s.static_box_veto = screens && o.temporal.static_box_veto;
  s.motion_screening = screens && o.temporal.motion_screening;
  return s;
}

ScreeningPipeline::ScreeningPipeline(const ScreeningOptions& options) : screener_(options) {
  const Stages stages = stagesFor(options);
  if (stages.box_tracking) box_tracker_ = std::make_unique<BoxTracker>(options.tracker);
  // A vetoed box also keeps what screening beyond the boxes dropped past it.
  const double veto_reach = options.no_depth_hole_radius_px > 0 ? options.grow_outside : 0.0;
  if (stages.temporal())
    temporal_ = std::make_unique<TemporalScreening>(options.temporal, options.box_dilation, veto_reach);
}

PipelineResult ScreeningPipeline::process(features::FeatureFrame& frame,
                                          const detection::Boxes& detections,
                                          const CameraModel& cam, const cv::Mat& depth_m, bool detector_ran) {
  PipelineResult r;
  r.boxes = box_tracker_ ? box_tracker_->predict(frame, detections, detector_ran) : detections;
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
