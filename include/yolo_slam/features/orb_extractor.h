#pragma once
// ORB feature extraction with ORB-SLAM2's behaviour: a scale pyramid, FAST corners found per
// 30 px cell with a fallback threshold, a quadtree that spreads the keypoints evenly over each
// level, intensity-centroid orientation and rotated BRIEF (256 bits) on a blurred image.
#include <opencv2/core.hpp>

#include <algorithm>
#include <string>
#include <vector>

namespace yolo_slam {

class Config;

namespace features {

struct OrbOptions {
  // Fewer keypoints cannot hold a pose (ORB-SLAM2 needs 30 inliers after matching and outlier
  // rejection, a fraction of what is extracted): below this nFeatures is a typo.
  static constexpr int kMinFeatures = 100;
  int n_features = 1000;      // ORBextractor.nFeatures: total over all levels, >= kMinFeatures
  double scale_factor = 1.2;  // ORBextractor.scaleFactor: between consecutive levels (> 1)
  int n_levels = 8;           // ORBextractor.nLevels
  int ini_th_fast = 20;       // ORBextractor.iniThFAST: FAST threshold tried first in a cell
  int min_th_fast = 7;        // ORBextractor.minThFAST: fallback when a cell has no corner
  // ORBextractor.dynamicBoostMax: when screening dropped more than a quarter of the last frame's
  // keypoints, the front end extracts up to this many times nFeatures so that about nFeatures
  // stay for SLAM (1: ORB-SLAM2's fixed budget). Crowds otherwise leave too few
  // static points to initialise and track; 3 lets a frame two thirds people keep nFeatures
  // (BENCHMARKS.md, "Session 37").
  double dynamic_boost_max = 3.0;
  // ORBextractor.threads: 2 extracts the pyramid levels on the caller's and a second thread
  // (level 0 beside the pyramid's construction, then the others shared; the same keypoints and
  // descriptors as 1); 1 extracts on the caller's thread only.
  static constexpr int kMaxThreads = 2;
  int threads = 2;

  // Reads the ORBextractor.* keys above (missing keys keep the defaults). Throws
  // yolo_slam::Error naming the file and key for out-of-range values.
  static OrbOptions load(const Config& cfg);
  // Throws yolo_slam::Error when a value is out of range; `where` prefixes the message.
  void validate(const std::string& where = "OrbOptions") const;
};

class OrbExtractor {
 public:
  static constexpr int kPatchSize = 31;       // BRIEF / orientation patch diameter
  static constexpr int kHalfPatchSize = 15;
  static constexpr int kEdgeThreshold = 19;   // keypoints stay this far from each level's border
  static constexpr int kCellSize = 30;        // FAST cell size in pixels (per level)
  static constexpr int kFastRadius = 3;       // FAST's Bresenham circle
  static constexpr int kDescriptorBytes = 32;  // 256 BRIEF tests

  explicit OrbExtractor(const OrbOptions& options);

  // The scale of a keypoint's pyramid level (its size is kPatchSize times it; at least 1):
  // pixel distances around a keypoint of a coarser level grow by it.
  static double levelScale(const cv::KeyPoint& kp) { return std::max(1.0, kp.size / double(kPatchSize)); }

  // gray: CV_8UC1 (throws yolo_slam::Error otherwise). Keypoints are in level-0 pixel
  // coordinates, ordered by level; octave = level, size = 31 * scale^level, angle in degrees
  // [0, 360), response = FAST score. descriptors: N x 32 CV_8U (0 x 32 when nothing is found).
  // Deterministic and thread-safe (const; no shared mutable state).
  void extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints,
               cv::Mat& descriptors) const;

  const OrbOptions& options() const { return options_; }
  const std::vector<double>& scaleFactors() const { return scale_factors_; }        // s^level
  const std::vector<double>& invScaleFactors() const { return inv_scale_factors_; }
  const std::vector<double>& levelSigma2() const { return level_sigma2_; }          // s^(2 level)
  const std::vector<double>& invLevelSigma2() const { return inv_level_sigma2_; }
  const std::vector<int>& featuresPerLevel() const { return features_per_level_; }

  // The 256 BRIEF test pairs (x1, y1, x2, y2 each), fixed for the lifetime of the program and
  // identical across platforms (own Gaussian sampler on std::mt19937 with a fixed seed).
  static const std::vector<cv::Point>& briefPattern();

 private:
  struct LevelFeatures {
    std::vector<cv::KeyPoint> keypoints;  // level-0 pixel coordinates, octave = level
    cv::Mat descriptors;                  // one row per keypoint
  };
  // Level l is the level l-1 resized by 1/scaleFactor; levels too small for a patch stay empty.
  std::vector<cv::Mat> buildPyramid(const cv::Mat& gray) const;
  std::vector<cv::KeyPoint> fastCorners(const cv::Mat& area) const;
  // Keypoints and descriptors of one pyramid level (img empty: none).
  void extractLevel(const cv::Mat& img, int level, LevelFeatures& out) const;
  // Every level into `levels` (one slot per level) on this thread and one helper.
  void extractOnTwoThreads(const cv::Mat& gray, std::vector<LevelFeatures>& levels) const;

  OrbOptions options_;
  std::vector<double> scale_factors_, inv_scale_factors_, level_sigma2_, inv_level_sigma2_;
  std::vector<int> features_per_level_;
  std::vector<int> umax_;  // half-width of the circular patch per row offset v = 0..15
};

}  // namespace features
}  // namespace yolo_slam
