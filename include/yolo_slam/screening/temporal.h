#pragma once
// Frame-to-frame evidence for screening (beyond the paper). Each keypoint is matched to the
// previous frame (ORB descriptor near its old position); the camera motion between the frames is
// estimated from the matched static keypoints with depth (3D-2D PnP RANSAC); a match that lands
// within static_tolerance_px of where its point would be if it were static is "static-consistent".
// Three uses, each with its own switch:
//
// - Label propagation (Screening.propagateLabels): a keypoint matched to a dynamic keypoint of
//   the previous frame that MOVED (not static-consistent) is dynamic too, box or no box. Most
//   dynamic keypoints screening misses lie outside every box (the detector loses people for a
//   few frames or clips an arm). Static background wrongly dropped inside boxes (static
//   retention is 55-70 %) is static-consistent and does not propagate. A label travels at most
//   propagate_max_age frames without screening confirming it.
// - Static-box veto (Screening.staticBoxVeto, on by default): a box scored below staticBoxMaxScore whose
//   dropped keypoints are nearly all (staticBoxFraction of those that can be tested, at least
//   staticBoxMinPoints) where static points would be is left alone (its keypoints kept): a false
//   detection (a picture, a poster) never moves. A seated person moves a fraction of a pixel per
//   frame and passes the motion test too, and keeping them ruins the map when they shift
//   (sitting_static 4.9 -> 53 mm without the score bound); but the detector is sure of them
//   (scores 0.97-1.0 there) and unsure of its false positives (static_xyz: 95 % below 0.8).
//
// - Motion screening (Screening.motionScreening, on by default): class-agnostic. A keypoint
//   that MOVED by at least motionMinResidual pixels against the camera motion, that no
//   lookalike keypoint of the previous frame explains as static (repeated texture), and that
//   has at least motionMinSupport moved neighbours within motionSupportRadius at a similar
//   depth, moving alike (motionFlowTolerance) and the majority (motionMinShare) of the tested
//   keypoints there, is dynamic, box or no box: people the detector missed or cut, and the
//   things they carry. Isolated or incoherent "moves" (false matches) drop nothing.
//
// Per frame, after Screener::screen:  temporal.apply(frame, boxes, cam);
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/json.h"
#include "yolo_slam/detection/box.h"
#include "yolo_slam/features/feature_frame.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace yolo_slam {

class Config;

namespace screening {

struct TemporalOptions {
  bool propagate_labels = false;
  // Frames a label travels without being confirmed by screening (1: one frame ahead only).
  int propagate_max_age = 3;
  bool static_box_veto = true;
  double static_box_fraction = 0.8;  // share of a box's tested dropped keypoints
  int static_box_min_points = 10;    // fewer tested keypoints: no verdict, the box stays
  double static_box_max_score = 0.8;  // boxes scored at least this are never vetoed
  // Pixel radius of the search around a keypoint's position in the previous frame (a walking
  // person moves tens of pixels per frame at 30 Hz).
  double radius_px = 30;
  // A match needs at most this Hamming distance (of 256 bits): ORB-SLAM2's TH_LOW.
  int max_hamming = features::kOrbHammingLow;
  // When both keypoints have depth, they must differ by at most this (metres) to be one point.
  double max_depth_change_m = 0.2;
  // A match closer than this (pixels at pyramid level 0, times the level's scale) to the
  // position predicted for a static point is static.
  double static_tolerance_px = 3;

  bool motion_screening = true;
  // A moved keypoint counts only this far (pixels at level 0, times the level's scale) from
  // its static position: twice the static tolerance, so that the band between stays untested.
  double motion_min_residual_px = 6;
  double motion_support_radius_px = 40;
  int motion_min_support = 3;          // other moved keypoints within the radius
  double motion_min_share = 0.5;       // moved share of the tested keypoints within the radius
  double motion_support_depth_m = 0.3; // neighbours count when their depth differs by at most this
  // Moved neighbours support a keypoint when their flows (pixels away from the static position)
  // differ by at most this or half its flow, whichever is more.
  double motion_flow_tolerance_px = 4;

  bool enabled() const { return propagate_labels || static_box_veto || motion_screening; }
  // Reads Screening.propagateLabels, propagateMaxAge, staticBoxVeto, staticBoxFraction,
  // staticBoxMinPoints, staticBoxMaxScore, temporalRadius (px), temporalMaxHamming (bits),
  // temporalMaxDepthChange (m), temporalStaticTolerance (px), motionScreening,
  // motionMinResidual (px), motionSupportRadius (px), motionMinSupport, motionMinShare,
  // motionSupportDepth (m), motionFlowTolerance (px); throws yolo_slam::Error naming the file and key.
  static TemporalOptions load(const Config& cfg);
  // The loader's rules, for options set in code; throws yolo_slam::Error prefixed by `where`.
  void validate(const std::string& where = "TemporalOptions") const;
};

// What apply() did to one frame, or (summed with +=) to a run of frames.
struct TemporalStats {
  int motion_frames = 0;        // frames whose camera motion was estimated (else nothing changes)
  int motion_inliers = 0;
  int matched = 0;              // keypoints matched to the previous frame
  int static_consistent = 0;    // of those, where a static point would be
  int propagated = 0;           // keypoints marked dynamic by label propagation
  int boxes_vetoed = 0;         // boxes left alone by the static-box veto
  int vetoed = 0;               // screened-dynamic keypoints they kept
  int motion_dropped = 0;       // keypoints marked dynamic by motion screening
  bool motionOk() const { return motion_frames > 0; }  // of one frame's stats
  TemporalStats& operator+=(const TemporalStats& o);
};
// {"matched", "static_consistent", "motion_frames", "motion_inliers", "propagated",
//  "boxes_vetoed", "vetoed", "motion_dropped"}
void to_json(Json& j, const TemporalStats& s);

// One per camera stream; deterministic. Not thread-safe: the caller serialises frames.
class TemporalScreening {
 public:
  // box_dilation: the screener's Screening.boxDilation, so the veto tests the regions it
  // screened. veto_reach: how far past that (fraction of the box's size per side) the screener
  // dropped keypoints for a box (Screening.growOutside, when screening beyond the boxes is
  // on): a vetoed box keeps those too. Validates the options.
  TemporalScreening(const TemporalOptions& options, double box_dilation, double veto_reach = 0);
  const TemporalOptions& options() const { return opt_; }

  // After Screener::screen on `frame` with `boxes`: the static-box veto, motion screening,
  // label propagation, then `frame` becomes the previous frame of the next call.
  TemporalStats apply(features::FeatureFrame& frame, const detection::Boxes& boxes,
                      const CameraModel& cam);
  void clear();

 private:
  // apply()'s phases. Matches of the current keypoints in the previous frame (-1: none).
  std::vector<int> matchPrevious(const features::FeatureFrame& frame, TemporalStats& st) const;
  // Per keypoint: -1 untested, 0 moved, 1 static-consistent; `flow` where it is minus where a
  // static point would be (pixels).
  std::vector<int8_t> motionVerdicts(const features::FeatureFrame& frame, const std::vector<int>& match,
                                     const CameraModel& cam, const cv::Matx33d& R, const cv::Vec3d& t,
                                     std::vector<cv::Point2f>& flow, TemporalStats& st) const;
  void vetoStaticBoxes(features::FeatureFrame& frame, const detection::Boxes& boxes,
                       const std::vector<int8_t>& verdict, TemporalStats& st) const;
  void screenMotion(features::FeatureFrame& frame, const std::vector<int8_t>& verdict,
                    const std::vector<cv::Point2f>& flow, const CameraModel& cam, const cv::Matx33d& R,
                    const cv::Vec3d& t, TemporalStats& st) const;
  // The previous frame's keypoints with depth where the camera motion puts them in the current
  // (undistorted) image, with their descriptors.
  features::FeatureFrame staticPositions(const CameraModel& cam, const cv::Matx33d& R, const cv::Vec3d& t) const;
  void propagate(features::FeatureFrame& frame, const std::vector<int>& match,
                 const std::vector<int8_t>& verdict, std::vector<int>& age, TemporalStats& st) const;
  void remember(const features::FeatureFrame& frame, const CameraModel& cam, std::vector<int> age);

  // Camera motion from the previous frame to the current one (X_cur = R X_prev + t) from the
  // matched pairs whose both ends are static; false when too few agree.
  bool estimateMotion(const features::FeatureFrame& frame, const std::vector<int>& match,
                      const CameraModel& cam, cv::Matx33d& R, cv::Vec3d& t, int& inliers) const;

  // Static pairs -> camera motion (EPnP RANSAC, then Levenberg-Marquardt on the inliers).
  static bool solveMotion(const std::vector<cv::Point3f>& obj, const std::vector<cv::Point2f>& img,
                          const CameraModel& cam, cv::Matx33d& R, cv::Vec3d& t, int* n_inliers);

  TemporalOptions opt_;
  double box_dilation_;
  double veto_reach_;
  features::FeatureFrame prev_;     // keypoints, descriptors, depth, dynamic of the last frame
  std::vector<cv::Point3f> prev_X_;  // its keypoints in its camera frame (z <= 0: no depth)
  std::vector<int> prev_age_;        // label age per keypoint (0: screened or static)
};

}  // namespace screening
}  // namespace yolo_slam
