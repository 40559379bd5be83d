#pragma once
// Box tracking between detections (beyond the paper): the detector misses people in some frames
// (rotated camera, partial views, blur) and the paper then screens nothing there. A BoxTracker
// remembers, per tracked person, the keypoints screened dynamic inside its box and, in a frame
// where no detection covers the track, moves its last box by the median displacement of those
// keypoints, found again by ORB descriptor near their old positions. One tracker per camera
// stream; deterministic (no RNG, tracks processed in id order).
// On by default (Screening.trackBoxes): on the full synthetic runs with the default detector
// it raised dynamic recall by 1-3 points (walking_xyz 88.3 -> 90.2 %, walking_rpy 86.4 -> 89.5 %)
// and lowered ATE on walking_xyz / walking_half; it also carries a few confident false
// positives (static_xyz: static keypoints dropped 2.2 -> 3.0 %). The ablation (docs/ablation.md,
// mode "detect+geometry:notrack") has the medians of both.
//
// Per frame:  boxes = tracker.predict(frame, detections);   // before Screener::screen
//             screener.screen(frame, boxes);
//             tracker.observe(frame);                        // after screening
#include "yolo_slam/detection/box.h"
#include "yolo_slam/features/feature_frame.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace yolo_slam {

class Config;

namespace screening {

struct BoxTrackerOptions {
  bool enabled = true;  // Screening.trackBoxes: track at all (modes with boxes only)
  // A track lives at most this many consecutive frames without a detection. Each carried frame
  // compounds the error of the box (the person also changes shape), so it is kept short.
  int max_age = 5;
  // Pixel radius around a remembered keypoint's old position searched for its match: bounds
  // the person's image motion per frame (TUM walking at 30 Hz: tens of pixels).
  double radius_px = 40;
  // A match needs at most this Hamming distance (of 256 bits): ORB-SLAM2's TH_LOW.
  int max_hamming = features::kOrbHammingLow;
  // Fewer matched keypoints than this: the person left the view or is hidden; drop the track
  // rather than trust a median of a handful of matches.
  int min_matches = 5;
  // Only tracks whose last detection scored at least this are carried. The detector's false
  // positives on static scenery score low (0.3-0.45 on walking_rpy, people missed in the next
  // frame scored 0.58-0.92) and carrying them would drop static keypoints for max_age frames.
  double min_score = 0.5;
  // Detection and track are the same object when the IoU of their boxes is at least this.
  double iou_associate = 0.3;
  // A predicted box whose area is at least this fraction inside a detection is that detection
  // (the detector's box changed shape too much for the IoU test): no duplicate box.
  double covered_fraction = 0.7;

  // Reads Screening.trackBoxes, trackMaxAge (frames), trackRadius (px), trackMaxHamming (bits),
  // trackMinMatches, trackMinScore; throws yolo_slam::Error naming the file and key.
  static BoxTrackerOptions load(const Config& cfg);
  // The loader's rules, for options set in code; throws yolo_slam::Error prefixed by `where`.
  void validate(const std::string& where = "BoxTrackerOptions") const;
};

class BoxTracker {
 public:
  explicit BoxTracker(const BoxTrackerOptions& options);  // validates
  const BoxTrackerOptions& options() const { return opt_; }

  // The boxes to screen in `frame`: every detection (unchanged, in order), then one box per
  // live track that no detection covers, moved by the median displacement of its remembered
  // keypoints matched into `frame` and clipped to the image; such boxes have tracked = true.
  // Tracks without enough matches, past max_age or moved out of the image are dropped.
  // Detections not associated to a track start new tracks.
  // detector_ran false: the detector did not look at this frame (asynchronous detection
  // between results): every track is carried, weak ones too, within max_age.
  detection::Boxes predict(const features::FeatureFrame& frame, const detection::Boxes& detections,
                           bool detector_ran = true);

  // After screening `frame` with the boxes of the last predict(): each track remembers the
  // keypoints flagged dynamic inside its box (positions + descriptors). A track with none left
  // is dropped when it is not detected in the next frame (min_matches fails).
  void observe(const features::FeatureFrame& frame);

  void clear() { tracks_.clear(); }
  size_t numTracks() const { return tracks_.size(); }

 private:
  struct Track {
    long id = 0;
    detection::Box box;              // box used in the current frame
    int age = 0;                     // frames since the last detection
    std::vector<cv::Point2f> pts;    // remembered dynamic keypoints (image pixels)
    cv::Mat desc;                    // their descriptors, rows match pts
  };
  // Median displacement of t's remembered keypoints matched into frame; false when fewer than
  // min_matches match.
  bool displacement(const Track& t, const features::FeatureFrame& frame, cv::Point2f& d) const;

  BoxTrackerOptions opt_;
  std::vector<Track> tracks_;  // ordered by id
  long next_id_ = 0;
};

// Intersection over union of two boxes (0 when either is empty).
double iou(const cv::Rect2f& a, const cv::Rect2f& b);

}  // namespace screening
}  // namespace yolo_slam
