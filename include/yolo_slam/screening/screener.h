#pragma once
// Dynamic-feature screening (YOLO-SLAM Algorithm 1, "depth-RANSAC"): inside each person box the
// largest set of keypoints whose depths agree (3-point depth variance under a threshold) is the
// person and is marked dynamic; the rest of the box stays static. See docs/screening.md for the
// meaning and units of the paper's nThre = 0.43 and the measurements behind the defaults.
#include "yolo_slam/detection/box.h"
#include "yolo_slam/features/feature_frame.h"

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
// refit: Algorithm 1, then the consensus depth interval is re-estimated from the whole consensus
//        set (mean +- refit_sigma * std, never narrower than the RANSAC acceptance interval) and
//        every in-box keypoint inside it is dynamic (a local-optimisation step as in LO-RANSAC:
//        the sampled pair is rarely at the centre of the person's depth range).
enum class ScreeningVariant { Paper, Refit };
ScreeningVariant parseScreeningVariant(const std::string& s);
std::string toString(ScreeningVariant v);

struct ScreeningOptions {
  DynamicMode mode = DynamicMode::DetectGeometry;
  ScreeningVariant variant = ScreeningVariant::Refit;
  // nThre: threshold on the population variance (Eq. 5) of the depths of the two sampled
  // keypoints plus the candidate (N = 3), in square metres. Default: see docs/screening.md.
  double variance_threshold_m2 = 0.43;
  double probability = 0.99;  // P of Eq. 7-8
  int max_iterations = 500;   // cap on k (k starts unbounded)
  unsigned seed = 0;          // RNG seed: screening is deterministic given the seed
  // Rule for in-box keypoints without valid depth (depth <= 0): true = dynamic (depth holes in
  // a person box sit mostly on the person's silhouette and hair), false = static.
  bool no_depth_dynamic = true;
  double box_dilation = 0.0;  // grow each box by this fraction of its width/height on every side
  double refit_sigma = 2.5;   // refit variant: half-width of the dynamic band in consensus stds

  // Reads Screening.mode, Screening.variant, Screening.varianceThreshold (m^2),
  // Screening.probability, Screening.maxIterations, Screening.seed, Screening.noDepth
  // ("dynamic" | "static"), Screening.boxDilation, Screening.refitSigma. Invalid values throw
  // yolo_slam::Error naming the file and key.
  static ScreeningOptions load(const Config& cfg);
  // Throws yolo_slam::Error (prefixed by `where`) if a value is out of range.
  void validate(const std::string& where = "ScreeningOptions") const;
};

struct ScreeningStats {
  int in_boxes = 0;    // keypoints inside at least one (dilated) box; geometry mode: all
  int kept = 0;        // of those, left static
  int dropped = 0;     // of those, marked dynamic
  int iterations = 0;  // RANSAC iterations summed over boxes
  double ms = 0;       // wall time of screen()
};

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
  ScreeningStats screen(features::FeatureFrame& frame, const detection::Boxes& boxes) const;

  // Algorithm 1 on a set of valid depths (metres, all > 0) with the given RNG seed.
  ConsensusResult depthRansac(const std::vector<float>& depths, unsigned seed) const;

 private:
  ScreeningOptions opt_;
};

// ---- Screening quality against ground truth (synthetic masks, the real TUM mask) ----------

struct ScreeningMetrics {
  int dynamic_total = 0;          // keypoints on the ground-truth mask
  int dynamic_dropped = 0;        // of those, marked dynamic
  int static_in_boxes = 0;        // keypoints off the mask inside at least one box
  int static_in_boxes_kept = 0;   // of those, left static
  int static_total = 0;           // keypoints off the mask anywhere
  int static_dropped = 0;         // of those, marked dynamic (false positives)

  // dynamic_dropped / dynamic_total (1 when there is no dynamic keypoint).
  double dynamicRecall() const;
  // static_in_boxes_kept / static_in_boxes (1 when there is no static keypoint in a box).
  double staticRetention() const;
  ScreeningMetrics& operator+=(const ScreeningMetrics& o);
  // {"dynamic_total":..,"dynamic_dropped":..,"dynamic_recall":..,"static_in_boxes":..,...}
  std::string toJson() const;
};

// Compares a screened frame with a ground-truth mask (CV_8UC1, same size as the image,
// > 127 = dynamic). Keypoint positions are frame.keypoints rounded to the nearest pixel.
// Throws yolo_slam::Error if the mask is empty, of another type or of another size.
ScreeningMetrics evaluateScreening(const features::FeatureFrame& frame, const cv::Mat& mask,
                                   const detection::Boxes& boxes);

// Reads a ground-truth mask PNG (8-bit, 0 static / 255 dynamic; colour images are converted to
// grey). Throws yolo_slam::Error naming the file if it is missing or unreadable.
cv::Mat loadMask(const std::string& path);

}  // namespace screening
}  // namespace yolo_slam
