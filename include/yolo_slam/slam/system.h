#pragma once
// The SLAM system: wires extraction, screening, tracking (caller's thread), local mapping and
// loop closing (own threads, or with System.sequential inline after each frame: deterministic).
// The one object driven by the offline runner and the ROS nodelets.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/common/json.h"
#include "yolo_slam/detection/box.h"
#include "yolo_slam/features/feature_frame.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/frontend/front_end.h"
#include "yolo_slam/mapping/dense_mapper.h"
#include "yolo_slam/screening/screener.h"
#include "yolo_slam/slam/map_file.h"
#include "yolo_slam/slam/options.h"
#include "yolo_slam/slam/track_result.h"
#include "yolo_slam/slam/types.h"

#include <opencv2/core.hpp>

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace yolo_slam {

class Config;

namespace vocabulary {
class Vocabulary;
class KeyFrameDatabase;
}

namespace slam {

class Map;
class Tracking;
class LocalMapping;
class LoopClosing;

struct MapSnapshot {
  std::vector<Eigen::Vector3d> points;                 // static map points only, world frame
  Trajectory keyframes;                                // T_wc, sorted by keyframe id
  std::vector<std::pair<int, int>> covisibility_edges; // indices into keyframes (weight >= kCovisibilityMinWeight)
};

// Boxes screened: from the detector, and carried by the BoxTracker (Screening.trackBoxes).
struct BoxCounts {
  long detected = 0, tracked = 0;
  BoxCounts& operator+=(const BoxCounts& o);
};
void to_json(Json& j, const BoxCounts& b);  // {"detected", "tracked"}

// Counters, per-stage stats summed over the frames, and timing samples (milliseconds) for
// stats.json.
// What a monitor polls every second (the ROS diagnostics): cheap, no per-frame samples copied.
struct LiveCounts {
  size_t keyframes = 0, map_points = 0;
  double local_mapping_median_ms = 0;  // per keyframe processed so far
  double map_lock_wait_max_ms = 0;     // longest wait of Tracking for the map lock, last frames
};

struct SystemStats {
  size_t frames = 0, tracked = 0, lost = 0, keyframes = 0, map_points = 0, resets = 0;
  size_t keyframes_culled = 0;
  size_t relocalizations = 0, loops_closed = 0, global_bas = 0;
  size_t jumps_refused = 0;  // poses refused as a jump from the motion model (Tracking.maxJump)
  size_t relocalizations_refused = 0;  // relocalised poses out of reach (Tracking.relocMaxSpeed)
  size_t tracked_from_prediction = 0;  // frames tracked from the prediction (Tracking.localMapFromPrediction)
  size_t young_points_dropped = 0;     // matches released by Tracking.youngPointCheck
  size_t prior_from_mean_step = 0;     // frames whose motion prior the mean step placed (Tracking.motionPriorFrames)
  size_t boxed_points_withheld = 0;    // keyframe points withheld by Tracking.boxedPointsStaticOnly and movedPointsWithheld
  size_t dropped_map_matches = 0;      // dropped keypoints static again by Tracking.droppedMapMatches
  size_t vo_frames = 0;                // localization mode: frames with temporary points (Tracking.voBelowMapPoints)
  // Frames not tracked because no map may start before the first detection (counted as lost).
  size_t awaiting_detection = 0;
  screening::ScreeningStats keypoints;  // Screener::screen
  screening::TemporalStats temporal;    // frame-to-frame evidence (propagateLabels, staticBoxVeto)
  BoxCounts boxes;
  double feature_budget_sum = 0;  // per frame nFeatures multiples extracted (ORBextractor.dynamicBoostMax)
  std::vector<double> extraction_ms, screening_ms, tracking_ms, local_mapping_ms, detection_ms;
  // Per frame: how long Tracking waited for the map lock (part of tracking_ms).
  std::vector<double> map_lock_wait_ms;
  // Per processed keyframe, by phase (LocalMappingTimings; total is local_mapping_ms).
  std::vector<double> lm_insert_ms, lm_fuse_ms, lm_ba_ms, lm_culling_ms;
};

// Per frame: extraction_ms + tracking_ms (the tracking thread's share of a frame).
std::vector<double> extractionPlusTrackingMs(const SystemStats& s);

// The counts of stats.json, shared by System::statsJson and yolo_slam_run: frames, tracked,
// lost, keyframes, keyframes_culled, map_points, map_resets, relocalizations, jumps_refused,
// relocalizations_refused, tracked_from_prediction, young_points_dropped, prior_from_mean_step, boxed_points_withheld, dropped_map_matches, vo_frames, loops_closed, global_bundle_adjustments, keypoints {...}, temporal
// {...}, boxes_screened {...},
// feature_budget_mean (nFeatures multiples extracted, mean over the frames).
Json statsCountsJson(const SystemStats& s);
// Per stage {"count", "median_ms", "mean_ms", "p95_ms"}: extraction, screening, tracking,
// extraction_plus_tracking, local_mapping, detection, map_lock_wait and the local-mapping
// phases (local_mapping_insert, _fuse, _ba, _culling), then `extra` stages measured by the caller.
Json statsTimingsJson(const SystemStats& s,
                      const std::vector<std::pair<std::string, std::vector<double>>>& extra = {});

// Everything System reads from the settings file, in one place (tools override fields, e.g. the
// runner's --dynamic-mode, before constructing the System).
struct SystemOptions {
  features::OrbOptions orb;              // ORBextractor.*
  screening::ScreeningOptions screening; // Screening.*
  SlamOptions slam;                      // Tracking.*, LocalMapping.*, LoopClosing.*
  mapping::DenseMapOptions dense;        // DenseMap.*: the dense static map (off by default)
  // System.sequential: local mapping, loop closing and the global BA after a loop run in the
  // caller's thread right after each tracked frame, not in their own threads, so identical
  // input gives bit-identical output (slower: the caller waits for the back end).
  bool sequential = false;
  // System.youngMapSync (threaded only): while the map is young (Tracking.youngMapFrames since
  // its initialisation) a frame that made a keyframe waits for local mapping to finish it, as
  // in sequential mode: a young map has few points, and the next frames need the ones local
  // mapping triangulates (a crowd covers most of the view).
  bool young_map_sync = true;
  static SystemOptions load(const Config& cfg);
};

// A frame extracted ahead of its screening and tracking (System::extractFrame).
struct ExtractedFrame {
  frontend::Extracted extracted;
  double stamp = 0;
  cv::Mat image, depth_m;  // the caller's image and usable depth, for the dense map
  std::string error;       // why the front end refused the frame (reported lost)
};

class System {
 public:
  // Reads the keys of SystemOptions from `cfg` (throws yolo_slam::Error naming the file and key
  // on bad values) and starts the mapping and loop-closing threads (none when sequential).
  System(const CameraModel& cam, const Config& cfg,
         std::shared_ptr<const vocabulary::Vocabulary> vocabulary /* may be null: no BoW */);
  System(const CameraModel& cam, const SystemOptions& options,
         std::shared_ptr<const vocabulary::Vocabulary> vocabulary);
  ~System();  // calls shutdown()
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // Extract + screen + track (sequential: then local mapping and loop closing). `image`:
  // BGR/RGB per Camera.RGB or gray; `depth_m`: CV_32F metres (0/NaN invalid) or empty. Bad
  // input (empty image, wrong depth size/type) is reported on stderr and the frame is reported
  // lost. A colour image whose size is not Camera.width x Camera.height throws yolo_slam::Error
  // (the settings belong to another camera: every pose would be wrong).
  // detector_ran false: `boxes` is empty because no detection was made for this frame
  // (asynchronous detection), so the box tracker carries every box.
  TrackResult trackRgbd(const cv::Mat& image, const cv::Mat& depth_m, double stamp,
                        const detection::Boxes& boxes, bool detector_ran = true);
  // trackRgbd in two halves, so that a caller can extract the next frame on another thread
  // while this one is screened and tracked (yolo_slam_run when not --sequential).
  // extractFrame is safe beside trackExtracted; it throws as trackRgbd on an image of the wrong
  // size and keeps other bad input in ExtractedFrame::error (the frame is then reported lost).
  // trackExtracted takes the frames in stream order.
  ExtractedFrame extractFrame(const cv::Mat& image, const cv::Mat& depth_m, double stamp);
  TrackResult trackExtracted(ExtractedFrame frame, const detection::Boxes& boxes, bool detector_ran = true);
  // Already extracted and screened (ROS Slam nodelet). Keypoints flagged dynamic are ignored.
  TrackResult trackFeatures(const features::FeatureFrame& frame);
  // Dense map (DenseMap.enabled): hands the keyframe the last trackFeatures made, with the
  // frame's colour image, depth (CV_32F metres) and person boxes, to the dense mapper (copies
  // them; the mapper masks and integrates in its own thread, or here when sequential). Call
  // right after the trackFeatures whose result it gets; trackRgbd does. Hands nothing over
  // unless res.keyframe_inserted and the dense map is on; when sequential, it integrates here
  // (and rebuilds after a loop) on every call.
  void addDenseKeyFrame(const TrackResult& res, const cv::Mat& image, const cv::Mat& depth_m,
                        const detection::Boxes& boxes);
  // The dense mapper, null when DenseMap.enabled is 0. Complete (final poses) after shutdown().
  const mapping::DenseMapper* denseMap() const { return dense_.get(); }

  void reset();
  void setLocalizationOnly(bool on);
  // Map files (slam/map_file.h, docs/map-file.md). saveMap writes the current map with this
  // System's camera, ORB pyramid and vocabulary identity; also after shutdown(). Throws
  // yolo_slam::Error if the file cannot be written.
  MapFileInfo saveMap(const std::string& path) const;
  // Replaces the map by the one in `path` and forgets the trajectory: tracking starts lost and
  // relocalises in the loaded map, so poses are in its world frame. The file is read into a new
  // Map first; on any problem (yolo_slam::Error naming the file and the fix) the running map and
  // tracking state are unchanged. Works before the first frame and with localization-only on.
  MapFileInfo loadMap(const std::string& path);
  bool localizationOnly() const;
  // Finishes queued keyframes, a pending loop correction and a running global BA, then stops
  // and joins the mapping and loop-closing threads; idempotent. (Sequential: nothing is left
  // pending between frames but keyframes queued while local mapping is paused, dropped here as
  // in threaded mode.)
  void shutdown();

  Trajectory cameraTrajectory() const;    // every tracked frame, T_wc
  Trajectory keyframeTrajectory() const;  // keyframes (also those of maps dropped by a reset)
  MapSnapshot mapSnapshot() const;
  std::string statsJson() const;
  SystemStats stats() const;  // copies every timing sample: for the end of a run
  LiveCounts liveCounts() const;

  // Extra API for tools and tests.
  // Blocks until local mapping has processed every queued keyframe (or is paused). Sequential:
  // returns at once, trackRgbd/trackFeatures have done it.
  void waitForLocalMapping();
  // Timing of the detector, measured by the caller that runs it (reported in the stats).
  void recordDetectionTime(double ms);
  TrackingState state() const;
  // Grows whenever the map's frame may have jumped under the camera: a reset, a map load, a
  // relocalisation, a loop closure or a global BA written back. Poses of two frames between
  // which it did not change differ by tracked motion only (slam::ContinuousOdometry).
  size_t mapCorrections() const;
  // Copy of the last frame trackRgbd extracted and screened (dynamic flags as set by the
  // screener), e.g. for screening metrics against ground truth; empty before the first frame.
  features::FeatureFrame lastFrame() const;
  // The boxes trackRgbd screened the last frame with: the caller's detections plus the boxes
  // carried by the BoxTracker (tracked = true); use them for screening metrics.
  detection::Boxes lastBoxes() const;
  // Blocks until loop closing has processed its queue and any global BA has finished.
  // Sequential: returns at once, as waitForLocalMapping.
  void waitForLoopClosing();
  bool sequential() const { return run_mode_ == RunMode::Sequential; }
  // (current keyframe id, loop keyframe id) of each loop closed so far.
  std::vector<std::pair<long, long>> loops() const;

 private:
  void resetInternal(bool keep_trajectory);
  // Counts a frame that is not tracked because no detection has been made yet (Stats).
  TrackResult skipAwaitingDetection();
  // Around a map replacement (reset, load): loop closing stopped and cleared, local mapping
  // parked and emptied; then both started again (local mapping unless localization-only).
  // Caller holds track_mutex_.
  void parkBackEnd();
  void resumeBackEnd();
  MapFileContext mapFileContext() const;
  // Sequential mode: local mapping, then loop closing, on what the last frame queued.
  void runBackEndInline();
  // Tracking.droppedMapMatches: the keypoints of the frame stamped `stamp` that tracking made
  // static again are static in lastFrame() too (what the screening metrics read).
  void markStaticAgain(double stamp, const std::vector<int>& keypoints);
  frontend::FrontEnd& frontEnd();  // made on first use

  CameraModel cam_;
  SlamOptions opt_;
  const RunMode run_mode_;
  const bool young_map_sync_;  // SystemOptions::young_map_sync
  features::OrbOptions orb_options_;
  screening::ScreeningOptions screening_options_;
  // Made by the first trackRgbd (trackFeatures callers, the ROS Slam nodelet, screen frames
  // elsewhere and never need one); serialises its own frames.
  std::once_flag front_end_once_;
  std::unique_ptr<frontend::FrontEnd> front_end_;
  std::shared_ptr<const vocabulary::Vocabulary> voc_;
  // Declared before map_: the map removes keyframes from it until destroyed.
  std::unique_ptr<vocabulary::KeyFrameDatabase> kfdb_;
  std::unique_ptr<Map> map_;
  std::unique_ptr<LocalMapping> mapper_;
  std::unique_ptr<LoopClosing> loop_closer_;   // null without vocabulary or when disabled
  std::unique_ptr<Tracking> tracker_;
  // Declared after map_ (destroyed first: its pose getters read the map's keyframes); stopped
  // in shutdown() after local mapping and loop closing, so its final rebuild sees final poses.
  std::unique_ptr<mapping::DenseMapper> dense_;

  // Serialises the tracking entry points (trackRgbd/trackFeatures/reset/setLocalizationOnly)
  // against each other; in sequential mode also the local mapping and loop closing they run
  // (held around runBackEndInline, which takes map->update_mutex only inside).
  // Lock order: track_mutex_, then map->update_mutex, then stats_mutex_.
  mutable std::mutex track_mutex_;
  // Guards stats_ (taken last, alone or after the mutexes above).
  mutable std::mutex stats_mutex_;
  SystemStats stats_;
  bool shut_down_ = false;
  size_t maps_loaded_ = 0;  // guarded by track_mutex_
  std::atomic<bool> localization_only_{false};
  // Guards last_frame_ (taken alone, never while holding another of the mutexes above).
  mutable std::mutex last_frame_mutex_;
  features::FeatureFrame last_frame_;
  detection::Boxes last_boxes_;  // also guarded by last_frame_mutex_
};

}  // namespace slam
}  // namespace yolo_slam
