#pragma once
// Dynamic-feature screening (YOLO-SLAM Algorithm 1, "depth-RANSAC"): inside each person box the
// largest set of keypoints whose depths agree (3-point depth variance under a threshold) is the
// person and is marked dynamic; the rest of the box stays static (variant "paper"). The default
// variant "nearest" takes the nearest sizeable depth cluster instead (people occlude the
// background). See docs/screening.md for the meaning and units of the paper's nThre = 0.43 and
// the measurements behind the defaults.
#include "yolo_slam/common/json.h"
#include "yolo_slam/detection/box.h"
#include "yolo_slam/features/feature_frame.h"
#include "yolo_slam/screening/box_tracker.h"
#include "yolo_slam/screening/temporal.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace yolo_slam {

class Config;

namespace screening {

// off: nothing dropped. detect: every keypoint inside a box is dropped (paper's "D").
// geometry: depth-RANSAC over the whole image, boxes ignored ("G").
// detect+geometry: depth-RANSAC inside each box (the paper's method, "D + G").
enum class DynamicMode { Off, Detect, Geometry, DetectGeometry };

// Parses "off" | "detect" | "geometry" | "detect+geometry"; throws yolo_slam::Error listing the
// accepted values otherwise.
DynamicMode parseDynamicMode(const std::string& s);
std::string toString(DynamicMode m);

// paper: Algorithm 1 as printed: the largest consensus set is dynamic, nothing else.
// grow: Algorithm 1, then the consensus set grows over the box's keypoints: a keypoint joins
//       when it lies within grow_radius_px pixels and grow_depth_m metres of depth of a member
//       (single linkage, to convergence). A person's depth spans 0.5 m and more (limbs, and a
//       camera tilted down sees the feet deeper than the torso), more than one variance window
//       holds without swallowing the background; depth-continuity in the image follows it.
// nearest: beyond the paper. The person is the NEAREST sizeable depth cluster of the box, not
//       the largest: a person occludes what is behind, so in a box where the background holds
//       more keypoints than the person (sitting people, loose or dilated boxes) the largest set
//       is the background. Clusters are depth windows of the same half-width as Algorithm 1's
//       consensus for a tight pair (sqrt(4.5 nThre)); the nearest window holding at least
//       cluster_min_fraction of the largest window's count is the person, then the grow step.
enum class ScreeningVariant { Paper, Grow, Nearest };
ScreeningVariant parseScreeningVariant(const std::string& s);
std::string toString(ScreeningVariant v);

struct ScreeningOptions {
  DynamicMode mode = DynamicMode::DetectGeometry;
  ScreeningVariant variant = ScreeningVariant::Nearest;
  // nThre: threshold on the population variance (Eq. 5) of the depths of the two sampled
  // keypoints plus the candidate (N = 3), in square metres. The paper's 0.43 read as m^2 merges
  // people with the desk behind them; 0.02 measured best (docs/screening.md).
  double variance_threshold_m2 = 0.02;
  double probability = 0.99;  // P of Eq. 7-8
  int max_iterations = 500;   // cap on k (k starts unbounded)
  unsigned seed = 0;          // RNG seed: screening is deterministic given the seed
  // Rule for in-box keypoints without valid depth (depth <= 0), Screening.noDepth:
  // Dynamic (depth holes in a person box sit mostly on the person's silhouette and hair);
  // Static; Nearest: the label of the nearest in-box keypoint with depth (within
  // grow_radius_px; static if none); NearDynamic (the default): dynamic when a keypoint with
  // depth declared dynamic lies within no_depth_radius_px, static otherwise (holes on a
  // person's outline have dynamic neighbours; far background beyond the sensor's range has none).
  enum class NoDepthRule { Dynamic, Static, Nearest, NearDynamic };
  NoDepthRule no_depth = NoDepthRule::NearDynamic;
  // Grow each box by this fraction of its width/height per side: detector boxes clip heads
  // and feet (measured gain with detector boxes, docs/screening.md).
  double box_dilation = 0.05;
  double grow_radius_px = 30;   // grow variant: pixel radius of the linkage
  double grow_depth_m = 0.1;    // grow variant: depth difference of the linkage (metres)
  // nearest variant: a depth cluster counts as "sizeable" when it holds at least this fraction
  // of the keypoints of the box's largest cluster.
  double cluster_min_fraction = 0.3;
  double no_depth_radius_px = 40;  // NearDynamic rule: radius in pixels
  // Silhouette rule (beyond the paper; box modes, needs the depth image passed to screen()): a
  // keypoint left static in a box whose own depth is missing or off the person's depth range,
  // but which has a depth pixel inside that range within this radius (pixels at pyramid level
  // 0, times the keypoint's scale), sits on the person's outline: its patch straddles the
  // moving person, and the depth sensor loses or smears the outline. 0 turns it off.
  double silhouette_radius_px = 2;
  // When true, the dilation ring around a box (box_dilation) only takes keypoints whose depth
  // joins the person's set; the no-depth rule applies inside the detected box only.
  bool dilation_depth_only = false;
  // Flat-box rule (screening/flat_box.h, beyond the paper; detect+geometry only): when the set
  // a box would drop lies on one plane (inverse depth affine in u, v) that continues into a
  // ring around the box (flat_box_fraction of the ring's keypoints with depth within
  // flat_box_tolerance 1/m of it), the box shows a picture or a static surface, not a person
  // in front of one: nothing in it is dropped. Keys Screening.rejectFlatBoxes,
  // flatBoxFraction, flatBoxTolerance (1/m), flatBoxRing (fraction of the box size per side).
  bool reject_flat_boxes = false;
  // Occlusion rule (beyond the paper): when the person set found in a box is mostly the person
  // set of another, overlapping box that its person fills better (a nearer person standing in
  // front of this box's person), this box is screened again without those keypoints, so that
  // the person behind is found too. Boxes overlapping by more than occlusion_max_iou are one
  // person detected twice and are left as they are. Screening.occlusionRule, occlusionMaxIou.
  bool occlusion_rule = true;
  double occlusion_max_iou = 0.5;
  // Screening beyond the boxes (person_mask.h; detect+geometry with the depth image passed to
  // screen()): each box's person set is grown over the depth image by depth continuity, up to
  // grow_outside of the box's width/height past each side of the box, and keypoints with
  // depth outside every box on the grown pixels are dropped (a box cuts off an arm, a head, a
  // carried object). Keypoints without depth are dropped only within no_depth_hole_radius_px
  // of a grown person pixel: outside the boxes that is a depth hole of the person's outline or
  // hair; inside a box it narrows the near-dynamic rule, whose holes far from the person are
  // mostly background beyond the sensor's range. Screening.growOutside (0 = no growth past the
  // box), Screening.noDepthHoleRadius (pixels; 0 turns both rules and the mask off).
  double grow_outside = 0.25;
  double no_depth_hole_radius_px = 20;
  // With the person mask above: a keypoint with depth inside a box that its box's screening
  // left static, lying on the grown pixels at a depth off the person range of every box that
  // holds it, is another person's: one standing behind the boxed person, beyond their own box
  // (the front box's nearest cluster is the front person). Screening.maskInBoxes; off by
  // default: on the crowd it raised recall on people by 0.3-0.9 points but not accuracy
  // (docs/screening.md, "A person behind the boxed one").
  bool mask_in_boxes = false;
  // Depth probe for keypoints without depth in a box (needs the depth image and the grown
  // person mask, so noDepthHoleRadius > 0): the nearest valid depth pixels around the keypoint
  // (the first square ring within this radius, pixels at level 0 times the keypoint's scale,
  // that holds any) decide. None on a grown person pixel: the hole is the background's
  // (projector shadow, far room beyond the sensor's range) and the keypoint stays static.
  // Nothing valid within the radius: near-dynamic decides as without the probe.
  // Screening.noDepthProbeRadius (pixels; 0 = off).
  double no_depth_probe_radius_px = 0;
  double flat_box_fraction = 0.4;
  double flat_box_tolerance = 0.01;
  double flat_box_ring = 0.25;
  // Box tracking between detections (box_tracker.h, beyond the paper): Screening.trackBoxes,
  // trackMaxAge, trackRadius, trackMaxHamming, trackMinMatches, trackMinScore.
  BoxTrackerOptions tracker;
  // Frame-to-frame evidence (temporal.h, beyond the paper): label propagation
  // (Screening.propagateLabels, propagateMaxAge), the static-box veto (staticBoxVeto,
  // staticBoxFraction, staticBoxMinPoints, staticBoxMaxScore), and the matching and static
  // test both use (temporalRadius, temporalMaxHamming, temporalMaxDepthChange,
  // temporalStaticTolerance).
  TemporalOptions temporal;

  // Reads Screening.mode, variant, varianceThreshold (m^2), probability, maxIterations, seed,
  // noDepth (dynamic | static | nearest | near-dynamic), noDepthRadius (px), silhouetteRadius
  // (px), boxDilation, growRadius (px), growDepth (m), clusterMinFraction, dilationDepthOnly,
  // rejectFlatBoxes, flatBoxFraction, flatBoxTolerance (1/m), flatBoxRing, occlusionRule,
  // occlusionMaxIou, growOutside, maskInBoxes, noDepthHoleRadius (px), noDepthProbeRadius (px), then the keys of
  // `tracker` and `temporal`. Invalid values throw yolo_slam::Error naming the file and key.
  static ScreeningOptions load(const Config& cfg);
  // The loader's rules, for options set in code (tracker and temporal included); throws
  // yolo_slam::Error prefixed by `where`.
  void validate(const std::string& where = "ScreeningOptions") const;
};

struct ScreeningStats {
  int in_boxes = 0;    // keypoints inside at least one (dilated) box; geometry mode: all
  int kept = 0;        // of those, left static
  int dropped = 0;     // of those, marked dynamic
  int iterations = 0;  // RANSAC iterations summed over boxes
  double ms = 0;       // wall time of screen()
  int flat_boxes = 0;  // boxes left alone by the flat-box rule (reject_flat_boxes)
  int silhouette = 0;  // of dropped, keypoints the silhouette rule dropped
  int occluded_boxes = 0;  // boxes screened again by the occlusion rule
  // Keypoints outside every box dropped by screening beyond the boxes (not in in_boxes;
  // counted before the static-box veto, which keeps them again when it vetoes their box):
  int grown_outside = 0;   // with depth, on a person's grown pixels
  int depth_holes = 0;     // without depth, within noDepthHoleRadius of them
  // Of dropped: keypoints in a box on another person's grown pixels (mask_in_boxes).
  int grown_in_boxes = 0;
  ScreeningStats& operator+=(const ScreeningStats& o);
};
// {"in_boxes", "kept", "dropped", "silhouette", "flat_boxes", "occluded_boxes", "grown_outside",
//  "grown_in_boxes", "depth_holes", "iterations"}
// (ms is timed apart).
void to_json(Json& j, const ScreeningStats& s);

// The box grown by fraction f of its width/height on each side (Screening.boxDilation).
cv::Rect2f dilate(const cv::Rect2f& r, double f);
// Whether p lies in r (right and bottom edges exclusive).
bool inside(const cv::Rect2f& r, const cv::Point2f& p);

// Eq. 8: k = log(1 - P) / log(1 - w^N). Returns +infinity when w <= 0 (no information yet) and
// 0 when w >= 1.
double adaptiveIterations(double inlier_ratio, double probability, int sample_size = 2);

// Result of Algorithm 1 on one set of depths (exposed for tests and tools).
struct ConsensusResult {
  std::vector<int> members;  // indices into the input depths declared dynamic
  int iterations = 0;
};

class Screener {
 public:
  explicit Screener(const ScreeningOptions& options);  // validates the options
  const ScreeningOptions& options() const { return opt_; }

  // Marks dynamic keypoints with frame.dynamic[i] = 1 (existing 1s are kept, so labels
  // propagated by the caller survive; frame.dynamic is resized to frame.size() if needed).
  // Box membership uses frame.keypoints (image pixel coordinates, like the boxes). Boxes are
  // all treated as dynamic-class boxes: the detector filters classes. Each call reseeds the
  // RNG from options().seed, so the result depends only on the frame and the boxes.
  // depth_m: the frame's depth image in metres (CV_32F, image size) for the silhouette rule
  // and screening beyond the boxes; empty leaves those rules out.
  ScreeningStats screen(features::FeatureFrame& frame, const detection::Boxes& boxes,
                        const cv::Mat& depth_m = cv::Mat()) const;

  // Algorithm 1 on a set of valid depths (metres, all > 0) with the given RNG seed (the paper
  // variant; the grow step needs pixel positions and runs in screen()).
  ConsensusResult depthRansac(const std::vector<float>& depths, unsigned seed) const;

  // The nearest variant's cluster choice on a set of valid depths (deterministic): indices of
  // the keypoints within sqrt(4.5 nThre) of the nearest window centre whose window holds at
  // least cluster_min_fraction of the largest window's count.
  std::vector<int> nearestCluster(const std::vector<float>& depths) const;

  // The grow step: extends `member` (flags over pts/depths, all depths > 0) by single linkage.
  void grow(const std::vector<cv::Point2f>& pts, const std::vector<float>& depths,
            std::vector<uint8_t>& member) const;

 private:
  ScreeningOptions opt_;
};

// ---- Screening quality against ground truth (synthetic masks, the real TUM mask) ----------

struct ScreeningMetrics {
  int dynamic_total = 0;          // keypoints on the ground-truth mask
  int dynamic_dropped = 0;        // of those, marked dynamic
  int dynamic_outside_boxes = 0;  // of dynamic_total, inside no box: only label propagation
                                  // (tracking, map points) can drop them
  int dynamic_outside_dropped = 0;  // of those, marked dynamic
  int person_total = 0;           // of dynamic_total, on a person (mask value 255)
  int person_dropped = 0;         // of those, marked dynamic
  int static_in_boxes = 0;        // keypoints off the mask inside at least one box
  int static_in_boxes_kept = 0;   // of those, left static
  int static_total = 0;           // keypoints off the mask anywhere
  int static_dropped = 0;         // of those, marked dynamic (false positives)
  // Of static_total, keypoints on a person's outline: their FAST circle (OrbExtractor::kFastRadius
  // pixels at their pyramid level) reaches a pixel of the mask, so the corner was made by the
  // moving outline and moves with it, though its centre pixel is off the mask.
  int static_on_outline = 0;
  int static_on_outline_dropped = 0;  // of those, marked dynamic

  // dynamic_dropped / dynamic_total (1 when there is no dynamic keypoint).
  double dynamicRecall() const;
  // person_dropped / person_total: the recall the issue defines ("keypoints on a person's
  // mask"); equal to dynamicRecall() unless the mask also shows other moving objects.
  double personRecall() const;
  // Recall over the dynamic keypoints inside at least one box (what screening decides).
  double dynamicRecallInBoxes() const;
  // static_in_boxes_kept / static_in_boxes (1 when there is no static keypoint in a box).
  double staticRetention() const;
  // static_dropped / static_total, and the same without the keypoints on an outline (0 when
  // there is no static keypoint).
  double staticDropRate() const;
  double staticDropRateOffOutline() const;
  ScreeningMetrics& operator+=(const ScreeningMetrics& o);
};
// {"dynamic_keypoints", "dropped", "dynamic_recall", "dynamic_outside_boxes",
//  "dynamic_outside_dropped", "dynamic_recall_in_boxes", "person_keypoints", "person_dropped",
//  "person_recall", "object_keypoints", "object_recall" (moving objects that are not people:
//  a carried or moved box), "static_in_boxes", "kept", "static_retention", "static_keypoints",
//  "static_dropped", "static_drop_rate", "static_on_outline", "static_on_outline_dropped",
//  "static_drop_rate_off_outline"}; a ratio without a denominator is null.
void to_json(Json& j, const ScreeningMetrics& m);

// Compares a screened frame with a ground-truth mask (CV_8UC1, same size as the image,
// > 127 = dynamic, 255 = a person; yolo_slam_synth writes 200 for other moving objects, the
// real TUM mask has 255 only). Keypoint positions are frame.keypoints rounded to the nearest
// pixel.
// ignore_border_px > 0 leaves out keypoints closer than that to the mask's boundary (on either
// side): hand-made or network masks are drawn loosely and depth is misregistered there, so
// those keypoints are neither clearly dynamic nor clearly static. Synthetic masks are exact:
// use 0. Throws yolo_slam::Error if the mask is empty, of another type or of another size.
ScreeningMetrics evaluateScreening(const features::FeatureFrame& frame, const cv::Mat& mask,
                                   const detection::Boxes& boxes, int ignore_border_px = 0);

// Reads a ground-truth mask PNG (8-bit, 0 static / 255 person / 128-254 other dynamic; colour
// images are converted to grey). Throws yolo_slam::Error naming the file if it is missing or
// unreadable.
cv::Mat loadMask(const std::string& path);

}  // namespace screening
}  // namespace yolo_slam
