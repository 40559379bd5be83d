#include "yolo_slam/slam/options.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/slam/types.h"

namespace yolo_slam {
namespace slam {

namespace {
int positiveInt(const Config& cfg, const std::string& key, int def, int min_value) {
  int v = cfg.getInt(key, def);
  if (v < min_value)
    throw Error(cfg.path() + ": key '" + key + "' must be >= " + std::to_string(min_value) +
                " (got " + std::to_string(v) + ")");
  return v;
}
double rangeDouble(const Config& cfg, const std::string& key, double def, double lo, double hi) {
  double v = cfg.getDouble(key, def);
  if (!(v >= lo && v <= hi))
    throw Error(cfg.path() + ": key '" + key + "' must be in [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "] (got " + std::to_string(v) + ")");
  return v;
}
}  // namespace

TrackingOptions TrackingOptions::load(const Config& cfg) {
  TrackingOptions o;
  o.init_min_keypoints = positiveInt(cfg, "Tracking.initMinKeyPoints", o.init_min_keypoints, 10);
  o.init_min_depth_points = positiveInt(cfg, "Tracking.initMinDepthPoints", o.init_min_depth_points, 10);
  o.motion_window = positiveInt(cfg, "Tracking.motionWindow", o.motion_window, 1);
  o.local_window = positiveInt(cfg, "Tracking.localWindow", o.local_window, 1);
  o.min_inliers = positiveInt(cfg, "Tracking.minInliers", o.min_inliers, 6);
  o.max_frames_between_kf = positiveInt(cfg, "Tracking.maxFrames", o.max_frames_between_kf, 0);
  o.min_frames_between_kf = positiveInt(cfg, "Tracking.minFrames", o.min_frames_between_kf, 0);
  o.ref_ratio = rangeDouble(cfg, "Tracking.refRatio", o.ref_ratio, 0.0, 1.0);
  o.close_tracked_max = positiveInt(cfg, "Tracking.closeTrackedMax", o.close_tracked_max, 0);
  o.close_untracked_min = positiveInt(cfg, "Tracking.closeUntrackedMin", o.close_untracked_min, 0);
  o.lost_reset_frames = positiveInt(cfg, "Tracking.lostResetFrames", o.lost_reset_frames, 1);
  o.lost_reset_max_keyframes = positiveInt(cfg, "Tracking.lostResetMaxKeyFrames", o.lost_reset_max_keyframes, 0);
  o.vo_points = positiveInt(cfg, "Tracking.voPoints", o.vo_points, 0);
  o.max_stamp_gap = rangeDouble(cfg, "Tracking.maxStampGap", o.max_stamp_gap, 1e-3, 1e6);
  return o;
}

LocalMappingOptions LocalMappingOptions::load(const Config& cfg) {
  LocalMappingOptions o;
  o.triangulation_neighbours = positiveInt(cfg, "LocalMapping.triangulationNeighbours", o.triangulation_neighbours, 1);
  o.fuse_neighbours = positiveInt(cfg, "LocalMapping.fuseNeighbours", o.fuse_neighbours, 1);
  o.culling_redundancy = rangeDouble(cfg, "LocalMapping.cullingRedundancy", o.culling_redundancy, 0.0, 1.0);
  o.local_ba = cfg.getBool("LocalMapping.localBA", o.local_ba);
  o.queue_size = positiveInt(cfg, "LocalMapping.queueSize", o.queue_size, 1);
  return o;
}

LoopClosingOptions LoopClosingOptions::load(const Config& cfg) {
  LoopClosingOptions o;
  o.enabled = cfg.getBool("LoopClosing.enabled", o.enabled);
  o.min_score = rangeDouble(cfg, "LoopClosing.minScore", o.min_score, 0.0, 1.0);
  o.consistency = positiveInt(cfg, "LoopClosing.consistency", o.consistency, 1);
  o.min_keyframes = positiveInt(cfg, "LoopClosing.minKeyFrames", o.min_keyframes, 0);
  o.min_bow_matches = positiveInt(cfg, "LoopClosing.minBowMatches", o.min_bow_matches, 6);
  o.min_ransac_inliers = positiveInt(cfg, "LoopClosing.minRansacInliers", o.min_ransac_inliers, 6);
  o.min_matches = positiveInt(cfg, "LoopClosing.minMatches", o.min_matches, 10);
  o.max_correction_m = rangeDouble(cfg, "LoopClosing.maxCorrectionM", o.max_correction_m, 0.0, 1e6);
  o.max_correction_deg = rangeDouble(cfg, "LoopClosing.maxCorrectionDeg", o.max_correction_deg, 0.0, 180.0);
  // Weaker pairs have no covisibility edge to take into the essential graph.
  o.covisibility_weight =
      positiveInt(cfg, "LoopClosing.covisibilityWeight", o.covisibility_weight, kCovisibilityMinWeight);
  o.pose_graph_iterations = positiveInt(cfg, "LoopClosing.poseGraphIterations", o.pose_graph_iterations, 1);
  o.global_ba = cfg.getBool("LoopClosing.globalBA", o.global_ba);
  o.global_ba_iterations = positiveInt(cfg, "LoopClosing.globalBAIterations", o.global_ba_iterations, 1);
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
