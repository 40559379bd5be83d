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
#include "yolo_slam/features/match_near.h"

#include <opencv2/core.hpp>

#include <deque>
#include <optional>
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
  // Asynchronous detection hands a frame boxes of an earlier image (detection::Box::age_s). A
  // detection of a track is moved by how far the track moved since that image: its box centre
  // then to now, summed from its keypoints' displacements frame by frame.
  bool shift_stale = true;
  // A track whose box covers at least this share of the image, and nine tenths of its height,
  // is a person near the camera. As a person comes to fill the view the detector's score falls
  // (0.3-0.5) and then it finds nothing, and blur and scale change defeat the keypoint matches:
  // such a track, once detected with at least min_score, is carried whatever its last score,
  // and where it cannot be matched its box stays where it was (within max_age). Nobody leaves a
  // view they fill in a frame or two. 1 turns it off.
  double near_fraction = 0.4;
  // A near track whose keypoints are still matched lives this many frames without a detection
  // (unmatched, max_age frames as any track): the detector can lose a person who fills the view
  // for a second or more (close seed 65: 17 frames), while their keypoints still move with them.
  int near_max_age = 30;

  // Reads Screening.trackBoxes, trackMaxAge (frames), trackRadius (px), trackMaxHamming (bits),
  // trackMinMatches, trackMinScore, trackShiftStale, trackNearFraction, trackNearMaxAge (frames);
  // throws yolo_slam::Error
  // naming the file and key.
  static BoxTrackerOptions load(const Config& cfg);
  // The loader's rules, for options set in code; throws yolo_slam::Error prefixed by `where`.
  void validate(const std::string& where = "BoxTrackerOptions") const;
};

class BoxTracker {
 public:
  explicit BoxTracker(const BoxTrackerOptions& options);  // validates
  const BoxTrackerOptions& options() const { return opt_; }

  // The boxes to screen in `frame`: every detection (in order; one older than the frame moved
  // with its track when shift_stale is on), then one box per
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
  struct Seen {
    double stamp;
    cv::Point2f travel;  // Track::travel after that frame
  };
  // Frames a track remembers its travel for: Detection.maxAge (0.2 s) at 30 Hz and more.
  static constexpr size_t kSeenFrames = 16;
  struct Track {
    long id = 0;
    detection::Box box;              // box used in the current frame
    int age = 0;                     // frames since the last detection
    int unmatched = 0;               // of them, the last ones carried without keypoint matches
    float best_score = 0.f;          // the highest score of the track's detections
    // A near person's track (isNearPersonBox) stays near while it is carried: its box, moved
    // and clipped at the image border each frame, shrinks, though the person still fills the view.
    bool near = false;
    std::vector<cv::Point2f> pts;    // remembered dynamic keypoints (image pixels)
    cv::Mat desc;                    // their descriptors, rows match pts
    std::optional<cv::Point2f> moved_now;  // keypoint displacement into the frame in predict()
    cv::Point2f travel{0.f, 0.f};    // sum of the keypoint displacements since the track began
    std::deque<Seen> seen;           // travel in the last kSeenFrames frames, oldest first
  };
  // Median displacement of t's remembered keypoints matched into the frame `index` holds; false
  // when fewer than min_matches match.
  bool displacement(const Track& t, const features::FeatureFrame& frame, const features::KeypointIndex& index,
                    cv::Point2f& d) const;
  // For each track, the detection associated to it (-1: none).
  std::vector<int> associate(const detection::Boxes& detections) const;
  // t's travel at `stamp` (a frame it saw, or between two), if it remembers that far back
  // without a frame whose motion was not measured.
  static std::optional<cv::Point2f> travelAt(const Track& t, double stamp);
  // `det`, associated to t, moved from where the detector saw the person to this frame.
  detection::Box placeDetection(const Track& t, const features::FeatureFrame& frame, const detection::Box& det) const;
  // Moves an undetected track into `frame`; false when it is dropped (too old, weak, lost, out
  // of view) or one of the `placed` detections already covers it.
  bool carry(Track& tr, const features::FeatureFrame& frame, const detection::Boxes& placed, bool detector_ran) const;

  BoxTrackerOptions opt_;
  std::vector<Track> tracks_;  // ordered by id
  // A detection of an earlier image has been seen (asynchronous detection): only then is every
  // track's travel measured in every frame (every-frame detection never needs it).
  bool stream_has_stale_ = false;
  long next_id_ = 0;
};

// Intersection over union of two boxes (0 when either is empty).
double iou(const cv::Rect2f& a, const cv::Rect2f& b);

// The box of a person near the camera (BoxTrackerOptions::near_fraction): it covers at least
// that share of a width x height image and nine tenths of its height (a person near the lens is
// cut by the image's top and bottom; the detector's wide false boxes over a rolled view are not).
bool isNearPersonBox(const cv::Rect2f& box, int width, int height, double near_fraction);

}  // namespace screening
}  // namespace yolo_slam
