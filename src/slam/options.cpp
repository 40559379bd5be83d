#include "yolo_slam/slam/options.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/slam/types.h"

namespace yolo_slam {
namespace slam {

namespace {

const OptionTable<TrackingOptions>& trackingFields() {
  using O = TrackingOptions;
  static const OptionTable<O> table = {
      {"Tracking.initMinKeyPoints", &O::init_min_keypoints, Range::atLeast(10)},
      {"Tracking.initMinDepthPoints", &O::init_min_depth_points, Range::atLeast(10)},
      {"Tracking.motionWindow", &O::motion_window, Range::atLeast(1)},
      {"Tracking.localWindow", &O::local_window, Range::atLeast(1)},
      {"Tracking.minInliers", &O::min_inliers, Range::atLeast(6)},
      {"Tracking.relocMinInliers", &O::reloc_min_inliers, Range::atLeast(6)},
      {"Tracking.maxFrames", &O::max_frames_between_kf, Range::atLeast(0)},
      {"Tracking.minFrames", &O::min_frames_between_kf, Range::atLeast(0)},
      {"Tracking.refRatio", &O::ref_ratio, Range::closed(0, 1)},
      {"Tracking.closeTrackedMax", &O::close_tracked_max, Range::atLeast(0)},
      {"Tracking.closeUntrackedMin", &O::close_untracked_min, Range::atLeast(0)},
      {"Tracking.closeMinFrames", &O::close_min_frames, Range::atLeast(0)},
      {"Tracking.keyFramePoints", &O::keyframe_points, Range::atLeast(0)},
      {"Tracking.lostResetFrames", &O::lost_reset_frames, Range::atLeast(1)},
      {"Tracking.lostResetMaxKeyFrames", &O::lost_reset_max_keyframes, Range::atLeast(0)},
      {"Tracking.youngMapFrames", &O::young_map_frames, Range::atLeast(1)},
      {"Tracking.youngLostResetFrames", &O::young_lost_reset_frames, Range::atLeast(0)},
      {"Tracking.voPoints", &O::vo_points, Range::atLeast(0)},
      {"Tracking.voBelowMapPoints", &O::vo_below_map_points, Range::atLeast(0)},
      {"Tracking.motionPrior", &O::motion_prior, Range::closed(0, 1e6)},
      {"Tracking.motionPriorDeg", &O::motion_prior_deg, Range::closed(0.01, 180)},
      {"Tracking.motionPriorFrames", &O::motion_prior_frames, Range::closed(1, 30)},
      {"Tracking.maxJump", &O::max_jump, Range::closed(0, 1e6)},
      {"Tracking.maxJumpDeg", &O::max_jump_deg, Range::closed(0, 180)},
      {"Tracking.maxJumpInliers", &O::max_jump_inliers, Range::atLeast(0)},
      {"Tracking.maxJumpLocalization", &O::max_jump_localization, Range::closed(0, 1e6)},
      {"Tracking.relocMaxSpeed", &O::reloc_max_speed, Range::closed(0, 1e6)},
      {"Tracking.relocMargin", &O::reloc_margin, Range::closed(0, 1e6)},
      {"Tracking.maxStampGap", &O::max_stamp_gap, Range::closed(1e-3, 1e6)},
      {"Tracking.localMapFromPrediction", &O::local_map_from_prediction},
      {"Tracking.youngPointCheck", &O::young_point_check},
      {"Tracking.boxedPointsStaticOnly", &O::boxed_points_static_only},
      {"Tracking.movedPointsWithheld", &O::moved_points_withheld},
      {"Tracking.droppedMapMatches", &O::dropped_map_matches, Range::atLeast(0)},
  };
  return table;
}

const OptionTable<LocalMappingOptions>& mappingFields() {
  using O = LocalMappingOptions;
  static const OptionTable<O> table = {
      {"LocalMapping.triangulationNeighbours", &O::triangulation_neighbours, Range::atLeast(1)},
      {"LocalMapping.fuseNeighbours", &O::fuse_neighbours, Range::atLeast(1)},
      {"LocalMapping.cullingRedundancy", &O::culling_redundancy, Range::closed(0, 1)},
      {"LocalMapping.freeSpaceRatio", &O::free_space_ratio, Range::closed(0, 1)},
      {"LocalMapping.localBA", &O::local_ba},
      {"LocalMapping.queueSize", &O::queue_size, Range::atLeast(1)},
      {"LocalMapping.threadNice", &O::thread_nice, Range::closed(0, 19)},
  };
  return table;
}

const OptionTable<LoopClosingOptions>& loopFields() {
  using O = LoopClosingOptions;
  static const OptionTable<O> table = {
      {"LoopClosing.enabled", &O::enabled},
      {"LoopClosing.minScore", &O::min_score, Range::closed(0, 1)},
      {"LoopClosing.consistency", &O::consistency, Range::atLeast(1)},
      {"LoopClosing.minKeyFrames", &O::min_keyframes, Range::atLeast(0)},
      {"LoopClosing.minBowMatches", &O::min_bow_matches, Range::atLeast(6)},
      {"LoopClosing.minRansacInliers", &O::min_ransac_inliers, Range::atLeast(6)},
      {"LoopClosing.minMatches", &O::min_matches, Range::atLeast(10)},
      {"LoopClosing.maxCorrectionM", &O::max_correction_m, Range::closed(0, 1e6)},
      {"LoopClosing.maxCorrectionDeg", &O::max_correction_deg, Range::closed(0, 180)},
      // Weaker pairs have no covisibility edge to take into the essential graph.
      {"LoopClosing.covisibilityWeight", &O::covisibility_weight, Range::atLeast(kCovisibilityMinWeight)},
      {"LoopClosing.poseGraphIterations", &O::pose_graph_iterations, Range::atLeast(1)},
      {"LoopClosing.globalBA", &O::global_ba},
      {"LoopClosing.globalBAIterations", &O::global_ba_iterations, Range::atLeast(1)},
      {"LoopClosing.threadNice", &O::thread_nice, Range::closed(0, 19)},
  };
  return table;
}

}  // namespace

TrackingOptions TrackingOptions::load(const Config& cfg) {
  TrackingOptions o;
  readOptions(cfg, o, trackingFields());
  return o;
}

LocalMappingOptions LocalMappingOptions::load(const Config& cfg) {
  LocalMappingOptions o;
  readOptions(cfg, o, mappingFields());
  return o;
}

LoopClosingOptions LoopClosingOptions::load(const Config& cfg) {
  LoopClosingOptions o;
  readOptions(cfg, o, loopFields());
  return o;
}

SlamOptions SlamOptions::load(const Config& cfg) {
  SlamOptions o;
  o.tracking = TrackingOptions::load(cfg);
  o.mapping = LocalMappingOptions::load(cfg);
  o.loop = LoopClosingOptions::load(cfg);
  return o;
}

}  // namespace slam
}  // namespace yolo_slam
