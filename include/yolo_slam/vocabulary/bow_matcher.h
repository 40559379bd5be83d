#pragma once
// Descriptor matching guided by the direct index (ORB-SLAM2's ORBmatcher::SearchByBoW): only
// features under the same vocabulary node are compared. For each usable feature of side A the
// best and second-best usable, not yet matched feature of side B under that node are found; a
// match is kept if best <= th_low and best < nn_ratio * second. Optionally the matches are
// filtered for rotation consistency (features::RotationHistogram with histogram_bins bins).
#include "yolo_slam/features/feature_frame.h"
#include "yolo_slam/vocabulary/bow_vector.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace yolo_slam {
namespace vocabulary {

struct BowMatchOptions {
  int th_low = features::kOrbHammingLow;
  float nn_ratio = 0.7f;     // ORB-SLAM2 ratio in SearchByBoW
  bool check_orientation = true;
  int histogram_bins = 30;   // ORB-SLAM2 HISTO_LENGTH
};

// One side of the matching. keypoints (for their .angle, degrees) are needed only with
// check_orientation; usable (nonzero = may be matched; e.g. has a map point / is static) may be
// null for "all".
struct BowSide {
  const FeatureVector* fv = nullptr;
  const cv::Mat* descriptors = nullptr;       // N x 32 CV_8U
  const std::vector<cv::KeyPoint>* keypoints = nullptr;
  const std::vector<uint8_t>* usable = nullptr;
};

struct BowMatch {
  unsigned a, b;  // feature indices into side A / side B
  int distance;
};

// Matches ordered by feature index of A; each index of A and of B appears at most once.
// Throws yolo_slam::Error if a side lacks fv/descriptors, or keypoints when orientation is
// checked, or if sizes disagree.
std::vector<BowMatch> searchByBow(const BowSide& a, const BowSide& b, const BowMatchOptions& options = {});

}  // namespace vocabulary
}  // namespace yolo_slam
