#pragma once
// Tracking (runs on the caller's thread): ORB-SLAM2's RGB-D front end. Initialisation from
// the first frame with enough depth, constant-velocity motion model, reference-keyframe
// fallback, local-map tracking, pose-only optimisation and the keyframe decision.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/features/feature_frame.h"
#include "yolo_slam/optimization/pose_optimizer.h"
#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/motion_model.h"
#include "yolo_slam/slam/options.h"
#include "yolo_slam/slam/track_result.h"
#include "yolo_slam/slam/types.h"

#include <memory>
#include <optional>
#include <vector>

namespace yolo_slam {
namespace vocabulary {
class Vocabulary;
}
namespace slam {

class LocalMapping;

// One output pose: relative to a reference keyframe, so that the trajectory follows the
// keyframe corrections of local BA (ORB-SLAM2 mlRelativeFramePoses). `ref` null: T_wc absolute.
struct FrameRecord {
  double stamp = 0;
  KeyFramePtr ref;
  Pose T_cr = Pose::Identity();
  Pose T_wc = Pose::Identity();
};

class Tracking {
 public:
  Tracking(const CameraModel& cam, const TrackingOptions& opt, Map& map, LocalMapping* mapper,
           std::shared_ptr<const vocabulary::Vocabulary> vocabulary,
           std::shared_ptr<const ScalePyramid> pyramid);

  // Tracks one frame. The caller holds map.update_mutex.
  TrackResult track(const features::FeatureFrame& ff);

  // True after track() when the map should be reset (lost for long with a small map).
  bool resetRequested() const { return reset_requested_; }
  // Forgets the map state (the map itself is cleared by System). Keeps the trajectory,
  // converted to absolute poses; the next map starts at the last tracked pose.
  void resetKeepTrajectory();
  // Full reset: trajectory too, next map starts at identity.
  void resetAll();
  // The map is being replaced by one loaded from a file: forgets everything as resetAll (not
  // counted as a reset) and starts lost, so the next frames relocalise in the loaded map instead
  // of initialising a new one.
  void startInLoadedMap();

  void setLocalizationOnly(bool on) { localization_only_ = on; }
  bool localizationOnly() const { return localization_only_; }
  TrackingState state() const { return state_; }
  // The last frame was tracked within young_map_frames of its map's initialisation.
  bool mapIsYoung() const;
  // The keyframe the last track() made (when its TrackResult says keyframe_inserted).
  const KeyFramePtr& lastKeyFrame() const { return last_kf_; }

  // Caller holds map.update_mutex.
  Trajectory trajectory() const;
  size_t frames() const { return frames_; }
  size_t trackedFrames() const { return tracked_; }
  size_t lostFrames() const { return lost_; }
  size_t resets() const { return resets_; }
  size_t relocalizations() const { return relocalizations_; }
  // Frames whose pose was refused as a jump from the motion model (Tracking.maxJump).
  size_t jumpsRefused() const { return jumps_refused_; }
  size_t relocalizationsRefused() const { return relocalizations_refused_; }
  // Frames tracked from the motion model's prediction alone (Tracking.localMapFromPrediction).
  size_t trackedFromPrediction() const { return from_prediction_; }
  // Matches of once-seen map points released by Tracking.youngPointCheck.
  size_t youngPointsDropped() const { return young_dropped_; }
  // Frames whose motion prior sat at the mean step's prediction (Tracking.motionPriorFrames).
  size_t priorFromMeanStep() const { return prior_mean_step_; }
  size_t boxedPointsWithheld() const { return boxed_withheld_; }
  // Dropped keypoints matched to map points and kept by the pose (Tracking.droppedMapMatches):
  // in all, and those of the last frame (indices into its keypoints).
  size_t droppedMatched() const { return dropped_matched_total_; }
  const std::vector<int>& lastDroppedMatched() const { return dropped_matched_; }
  // Localization mode: frames tracked with temporary points in the last frame (Tracking.voPoints,
  // voBelowMapPoints).
  size_t voFrames() const { return vo_frames_; }
  const Trajectory& frozenKeyFrames() const { return frozen_keyframes_; }
  // Called by System before the map is cleared: remembers the keyframe poses of the old map.
  void freezeKeyFrames(const Trajectory& kfs) { frozen_keyframes_.insert(frozen_keyframes_.end(), kfs.begin(), kfs.end()); }

 private:
  // All below run inside track(): the caller holds map.update_mutex.
  void checkTimestamp(const Frame& F);
  TrackResult trackFirst(Frame& F);   // not initialised yet: initialise on F
  // Motion model, reference keyframe or (lost) relocalisation, then the local map.
  bool trackFrame(Frame& F);
  // T_cw (tracked on inliers_) lies farther from the constant-velocity prediction than a camera
  // moves in a frame, on too few inliers to trust it (TrackingOptions::max_jump).
  bool implausibleJump(const Pose& T_cw, const Pose& prediction) const;
  bool refusedAsUnreachable(const Frame& F);
  // The motion prior for F (TrackingOptions::motion_prior), sigmas scaled by the frames since the
  // last frame.
  optimization::PosePrior motionPrior(const Frame& F, const Pose& prediction) const;
  void onTracked(Frame& F, TrackResult& res);
  void onFailed(TrackResult& res);
  // Reset rules of a lost map: lost for lost_reset_frames with at most lost_reset_max_keyframes
  // keyframes; lost within young_map_frames of the map's initialisation for
  // young_lost_reset_frames.
  bool lostLongInSmallMap() const;
  bool lostYoung() const;
  // Within young_map_frames of the initialisation of the map F is tracked in.
  bool youngMap(const Frame& F) const;
  // F becomes the last (good) frame and is recorded in the trajectory.
  void acceptFrame(const Frame& F, TrackResult& res);
  bool initialize(Frame& F);
  bool trackMotionModel(Frame& F);
  // Tracking.localMapFromPrediction: F starts at `prediction` without associations, so that
  // trackLocalMap searches the last frame's local map from there.
  void startFromPrediction(Frame& F, const Pose& prediction) const;
  // Whether F comes within max_frames_ (a second) of the last relocalisation (ORB-SLAM2's window).
  bool justRelocalized(const Frame& F) const;
  // Inliers the local-map step needs: Tracking.relocMinInliers shortly after a relocalisation.
  int minInliers(const Frame& F) const;
  // Whether a new keyframe may make a map point of keypoint i (Tracking.boxedPointsStaticOnly).
  bool mayMakeKeyFramePoint(const Frame& F, int i) const;
  bool trackReferenceKeyFrame(Frame& F, const KeyFramePtr& kf, const Pose& prior, int min_inliers);
  // Projection search of kf's static points not yet matched in F, window th.
  int searchKeyFramePoints(Frame& F, const KeyFrame& kf, double th) const;
  // Lost: a relocalisation over the whole map; else the last reference keyframe and its best
  // covisibles, each from the last good pose and then by PnP on its BoW matches (30 inliers).
  bool trackWhenLost(Frame& F);
  // ORB-SLAM2 Relocalization: BoW candidates from the map's KeyFrameDatabase, SearchByBoW,
  // PnP RANSAC, pose optimisation, projection search for more matches; needs >= 50 inliers.
  bool relocalize(Frame& F);
  // One candidate: BoW matches, PnP, at least min_inliers after the pose optimisation.
  bool relocalizeOn(Frame& F, const KeyFramePtr& kf, int min_inliers);
  // F was relocalised on kf: the new reference, no velocity, the stricter local-map step.
  void acceptRelocalization(const Frame& F, const KeyFramePtr& kf);
  // PnP RANSAC on F's associations; sets the pose and keeps the inliers' associations.
  bool pnpPose(Frame& F) const;
  bool trackLocalMap(Frame& F);
  // Tracking.youngPointCheck (young_points.h): releases the matches of young points that
  // disagree with the pose of the confirmed points alone; returns how many.
  int dropDisagreeingYoungPoints(Frame& F);
  // Re-anchors the last frame on its (possibly refined or erased) reference keyframe.
  void updateLastFrame();
  // Localization mode: temporary close points in the last frame for visual odometry, when it
  // tracked fewer than Tracking.voBelowMapPoints map points.
  void addTemporaryPoints();
  // The last frame's static keypoints with depth not seen moving (Frame::seenMoving), nearest
  // first: all closer than ThDepth, at least Tracking.voPoints.
  void addTemporaryCloseFirst();
  void updateLocalMap(Frame& F);
  void searchLocalPoints(Frame& F);
  int optimizePose(Frame& F);
  // Tracking.droppedMapMatches: the dropped keypoints matched in the local-map search that the
  // pose did not keep are dynamic again.
  void settleDroppedMatches(Frame& F);
  // Pose-only optimisation, then the outlier matches are released; returns the matches to
  // points that are in the map (motion-model and reference-keyframe tracking).
  int optimizePoseAndDropOutliers(Frame& F);
  // A map point from keypoint i of F (with depth), observed by kf; caller holds the map mutex.
  // Returns false when the keypoint cannot be back-projected.
  bool createDepthPoint(const KeyFramePtr& kf, Frame& F, int i);
  // No velocity: the constant-velocity model starts again from the next tracked frames.
  void forgetMotion();
  Pose priorPrediction(const Pose& prediction);
  bool needNewKeyFrame(const Frame& F) const;
  void createNewKeyFrame(Frame& F);
  void record(const Frame& F);

  CameraModel cam_;
  TrackingOptions opt_;
  Map& map_;
  LocalMapping* mapper_;
  std::shared_ptr<const vocabulary::Vocabulary> voc_;
  std::shared_ptr<const ScalePyramid> pyr_;
  FrameGeometry geom_;
  int max_frames_ = 30, min_frames_ = 0;

  TrackingState state_ = TrackingState::NotInitialized;
  bool localization_only_ = false;
  long next_frame_id_ = 0;
  Frame last_;
  bool has_last_ = false;
  KeyFramePtr ref_kf_;          // reference keyframe of the current frame
  KeyFramePtr last_kf_;         // the newest keyframe made
  long last_kf_frame_id_ = -1;
  Pose T_lr_ = Pose::Identity();   // last frame relative to its reference keyframe
  KeyFramePtr last_ref_;
  bool has_velocity_ = false;
  Pose velocity_ = Pose::Identity();  // T_cl: current from last
  MotionHistory recent_;              // consecutive tracked frames, for the prior's prediction
  int inliers_ = 0;
  int failures_in_row_ = 0;
  int lost_frames_in_row_ = 0;
  double last_stamp_ = 0;
  bool has_last_stamp_ = false;
  Pose last_good_T_wc_ = Pose::Identity();
  bool has_last_good_ = false;
  bool reset_requested_ = false;
  long init_frame_id_ = -1;     // the frame this map was initialised at (-1: loaded or none)
  long last_tracked_id_ = -1;   // the last frame tracked in this map
  std::vector<KeyFramePtr> local_kfs_;
  std::vector<MapPointPtr> local_points_;
  std::vector<MapPointPtr> dynamic_hits_;
  std::vector<MapPointPtr> temporary_points_;

  std::vector<FrameRecord> records_;
  Trajectory frozen_keyframes_;
  long last_reloc_frame_id_ = -1;
  // Set by trackFrame while it tracks a frame the motion model predicts; every pose
  // optimisation of that frame uses it.
  std::optional<optimization::PosePrior> prior_;
  size_t frames_ = 0, tracked_ = 0, lost_ = 0, resets_ = 0, relocalizations_ = 0, jumps_refused_ = 0;
  size_t relocalizations_refused_ = 0;
  size_t from_prediction_ = 0;
  size_t young_dropped_ = 0;  // matches released by the young-point check
  size_t prior_mean_step_ = 0;  // frames whose prior the mean step placed
  size_t boxed_withheld_ = 0;  // keyframe points withheld by Tracking.boxedPointsStaticOnly / movedPointsWithheld
  std::vector<int> dropped_matched_;   // this frame's dropped keypoints matched to map points
  size_t dropped_matched_total_ = 0;
  size_t vo_frames_ = 0;       // frames whose last frame got temporary points
  long init_kf_id_ = -1;      // the first keyframe of the map being built (-1: a loaded map)
};

}  // namespace slam
}  // namespace yolo_slam
