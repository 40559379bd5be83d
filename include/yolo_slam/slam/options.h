#pragma once
// Options of the SLAM core (tracking, local mapping, loop closing), read from the Tracking.*,
// LocalMapping.* and LoopClosing.* keys. Defaults are ORB-SLAM2's constants for RGB-D.
#include <string>

namespace yolo_slam {

class Config;

namespace slam {

struct TrackingOptions {
  // Initialisation as ORB-SLAM2 (N > 500), counting static keypoints only (screened ones are
  // gone), and requiring enough of them with depth to seed a usable map.
  int init_min_keypoints = 500;     // Tracking.initMinKeyPoints: static keypoints to initialise
  int init_min_depth_points = 100;  // Tracking.initMinDepthPoints: of those, with valid depth
  int motion_window = 15;           // Tracking.motionWindow: projection radius (px, level 0) of the motion model
  int local_window = 3;             // Tracking.localWindow: radius factor for the local-map search (RGB-D: 3)
  int min_inliers = 30;             // Tracking.minInliers: below this after local-map tracking the frame fails
  // Tracking.relocMinInliers: within maxFrames frames of a relocalisation the frame fails below
  // this many (ORB-SLAM2's TrackLocalMap: 50). A relocalised pose rests on one keyframe's
  // matches; where people fill most of the view the next frames can follow a person's keypoints
  // the boxes missed with 30-50 inliers.
  int reloc_min_inliers = 50;
  int max_frames_between_kf = 0;    // Tracking.maxFrames: 0 = camera fps (ORB-SLAM2)
  int min_frames_between_kf = 0;    // Tracking.minFrames
  double ref_ratio = 0.75;          // Tracking.refRatio: keyframe if tracked < ratio * reference's points
  int close_tracked_max = 100;      // Tracking.closeTrackedMax: close-point criterion (tracked < this
  int close_untracked_min = 70;     // Tracking.closeUntrackedMin:  and untracked > this)
  int close_min_frames = 5;         // Tracking.closeMinFrames: frames since the last keyframe before
                                    //   the close-point criterion of a mature map may ask for one (0: ORB-SLAM2)
  // Tracking.keyFramePoints: a new keyframe makes map points of its static keypoints with depth,
  // the closest first: all nearer than ThDepth and at least this many (ORB-SLAM2: 100). Where
  // most of the view lies beyond ThDepth (3 m on the TUM cameras) 100 leave a sparse local map.
  int keyframe_points = 300;
  int lost_reset_frames = 150;      // Tracking.lostResetFrames: lost for this many frames ...
  int lost_reset_max_keyframes = 5; // Tracking.lostResetMaxKeyFrames: ... with a map this small: reset
  // A young map (lost within young_map_frames frames of its initialisation) is reset after
  // young_lost_reset_frames lost frames, whatever its size: a map made while people covered
  // much of the view holds few static points and rarely relocalises (crowd preset, issue 23);
  // a new one starts at the last good pose, which the camera has left by the lost frames'
  // motion: a sound young map relocalises once the people move on (crowd seed 7: after 8
  // frames), so the reset waits a third of a second. 0 turns it off.
  int young_map_frames = 30;        // Tracking.youngMapFrames
  int young_lost_reset_frames = 10; // Tracking.youngLostResetFrames
  int vo_points = 100;              // Tracking.voPoints: temporary close points in the last frame
  // Localization mode makes them only when the last frame tracked fewer map points than this
  // (ORB-SLAM2 makes them on every frame: a large value), and never of a keypoint the
  // frame-to-frame test found moved or of one kept static in a person box without that test
  // finding it static. With enough map points they add little but the people screening missed,
  // who pull the pose along (crowd seed 1 in a map of its empty room: 45 mm -> 6 mm).
  int vo_below_map_points = 50;     // Tracking.voBelowMapPoints
  // Motion prior (beyond ORB-SLAM2): a frame tracked with the motion model is optimised with a
  // Gaussian prior at the constant-velocity prediction, sigma motionPrior metres for the camera
  // centre and motionPriorDeg degrees, times the frames since the last one. Strong static
  // support outweighs it; it holds the directions a sliver of far static scene (people filling
  // the view) leaves unconstrained. Both sigmas sit near the 95th percentile of how far the real
  // fr3_walking_xyz camera moves from the prediction in a frame (3.9 mm, 1.06 degrees): where a
  // far wall cannot tell a sideways shift from a turn, the prior then favours neither (test
  // MotionPrior.*; with 2 cm a crowd's sideways walk became a turn: BENCHMARKS.md, "Session
  // 41"). 0 = off.
  double motion_prior = 0.005;      // Tracking.motionPrior (m)
  double motion_prior_deg = 1.0;    // Tracking.motionPriorDeg
  // The prior's prediction: the last frame step (ORB-SLAM2's constant-velocity model, which the
  // motion-model search always uses), or the mean of the last motionPriorFrames steps when the
  // two predictions lie more than 3 sigmas apart (slam/motion_model.h); 1 = the last step always.
  // Off by default: 4 helps held-out crowds and people at the lens but broke the young-point
  // check's hold on an unscreened walker (BENCHMARKS.md, "Session 43").
  int motion_prior_frames = 1;      // Tracking.motionPriorFrames
  // maxJump > 0: a pose that lands more than maxJump metres (or maxJumpDeg degrees) from the
  // constant-velocity prediction on fewer than maxJumpInliers inliers is refused (the frame
  // fails), for a robot that would rather be lost than jump. Off by default: with the motion
  // prior it changed nothing on the close preset and lost a frame in the crowd.
  double max_jump = 0.0;            // Tracking.maxJump (m)
  double max_jump_deg = 10.0;       // Tracking.maxJumpDeg
  int max_jump_inliers = 100;       // Tracking.maxJumpInliers
  // maxJump in localization mode. There the loaded map is trusted and nothing is added to it: a
  // refused pose costs a relocalisation in a good map, a kept one that a crowd dragged off costs
  // the robot its place (held-out crowd seed 51: 0.31 m off, 29 mm RMSE; 6 mm with 0.05).
  double max_jump_localization = 0.05;  // Tracking.maxJumpLocalization (m)
  // Beyond ORB-SLAM2: a pose found while lost (a relocalisation, or the last keyframes tracked
  // from the last good pose) farther from the last tracked pose than relocMaxSpeed times the
  // time since that frame, plus relocMargin, is refused and the frame stays lost: a camera cannot
  // get there, and a place recognised wrongly on the few keypoints a person leaving the lens lets
  // through moved a held-out run by 0.7-0.9 m. 0: off (ORB-SLAM2).
  double reloc_max_speed = 1.5;     // Tracking.relocMaxSpeed (m/s)
  double reloc_margin = 0.15;       // Tracking.relocMargin (m)
  double max_stamp_gap = 1.0;       // Tracking.maxStampGap (s): a larger gap drops the motion model
  // Beyond ORB-SLAM2: when the motion model and the reference keyframe both fail on a frame the
  // constant-velocity model predicts, the local map is searched from the prediction (the
  // local-map step, min_inliers as always). A person crossing close to the camera hides what
  // the last frame and the reference keyframe saw, while the local map holds the room behind.
  bool local_map_from_prediction = true;  // Tracking.localMapFromPrediction
  // Beyond ORB-SLAM2: young map points (made by one of the last keyframes, or seen by one
  // keyframe only; young_points.h) must agree with the pose the confirmed points give alone, or
  // they are not matched in this frame. A person the screening missed when a keyframe was made
  // is otherwise in the map at once, and the next frames' poses follow the person.
  bool young_point_check = true;  // Tracking.youngPointCheck
  // Beyond ORB-SLAM2: past a map's first young_map_frames frames, a keypoint screened static
  // inside a person box (FeatureFrame::boxed) gives a new keyframe a map point only when the
  // frame-to-frame test found it where a static point would be (FeatureFrame::motion 1). The screening keeps what lies behind the boxed person's
  // depth cluster: mostly the room, sometimes a person the detector missed behind the boxed
  // one, whose points would pull the next frames' poses. They still match existing map points.
  bool boxed_points_static_only = true;  // Tracking.boxedPointsStaticOnly
  // Beyond ORB-SLAM2: past a map's first young_map_frames frames, a keypoint the frame-to-frame
  // test saw move (FeatureFrame::motion 0: not where a static point would be), inside a box or
  // not, gives a new keyframe no map point. People the screening missed are what moves; their
  // points would pull the next frames' poses. They still match existing map points.
  bool moved_points_withheld = true;  // Tracking.movedPointsWithheld
  // Beyond ORB-SLAM2, localization mode only: in the local-map search, a map point seen by at
  // least this many keyframes that finds no static keypoint may match a keypoint the screening
  // dropped, if the frame-to-frame test did not see it move and it lies at the point's depth (or
  // has none); it is static again when the pose keeps it as an inlier (matcher::DroppedMatching).
  // The room behind a person's box matches its own points of the loaded map. 0: off.
  int dropped_map_matches = 3;  // Tracking.droppedMapMatches

  static TrackingOptions load(const Config& cfg);
};

struct LocalMappingOptions {
  int triangulation_neighbours = 10;  // LocalMapping.triangulationNeighbours (ORB-SLAM2: 10 stereo/RGB-D)
  int fuse_neighbours = 10;           // LocalMapping.fuseNeighbours
  double culling_redundancy = 0.9;    // LocalMapping.cullingRedundancy: keyframe culled if this share
                                      // of its points is seen by >= 3 other keyframes
  double free_space_ratio = 0.5;      // LocalMapping.freeSpaceRatio: a point triangulated for a
                                      // keypoint without depth nearer than this share of the
                                      // depth measured around it is refused (0: off, ORB-SLAM2)
  bool local_ba = true;               // LocalMapping.localBA
  int queue_size = 3;                 // LocalMapping.queueSize: bounded keyframe queue
  int thread_nice = 10;               // LocalMapping.threadNice: the local BA's solve runs on a
                                      // helper thread this much nicer than the process (0: inline)

  static LocalMappingOptions load(const Config& cfg);
};

// Loop closing (ORB-SLAM2 LoopClosing with SE3 instead of Sim3: RGB-D has metric scale).
struct LoopClosingOptions {
  bool enabled = true;               // LoopClosing.enabled (needs a vocabulary)
  double min_score = 0.0;            // LoopClosing.minScore: floor of the BoW score; the bar is
                                     // max(this, lowest score against the keyframe's covisibles)
  int consistency = 3;               // LoopClosing.consistency: consecutive keyframes agreeing
  int min_keyframes = 10;            // LoopClosing.minKeyFrames: map size / keyframes since last loop
  int min_bow_matches = 20;          // LoopClosing.minBowMatches: SearchByBoW matches per candidate
  int min_ransac_inliers = 20;       // LoopClosing.minRansacInliers: 3D-3D RANSAC inliers
  int min_matches = 40;              // LoopClosing.minMatches: after the projection search
  double max_correction_m = 0.5;     // LoopClosing.maxCorrectionM: larger pose corrections are
  double max_correction_deg = 20.0;  // LoopClosing.maxCorrectionDeg: taken for perceptual aliasing
  int covisibility_weight = 100;     // LoopClosing.covisibilityWeight: essential-graph covisibility edges
  int pose_graph_iterations = 20;    // LoopClosing.poseGraphIterations
  bool global_ba = true;             // LoopClosing.globalBA: full BA in its own thread after a loop
  int thread_nice = 10;              // LoopClosing.threadNice: the global BA's solve runs on a
                                     // helper thread this much nicer than the process
  int global_ba_iterations = 10;     // LoopClosing.globalBAIterations

  static LoopClosingOptions load(const Config& cfg);
};

struct SlamOptions {
  TrackingOptions tracking;
  LocalMappingOptions mapping;
  LoopClosingOptions loop;
  static SlamOptions load(const Config& cfg);
};

}  // namespace slam
}  // namespace yolo_slam
