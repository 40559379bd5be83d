#pragma once
// Finds a remembered keypoint again in a new frame: the keypoint within a pixel radius of its old
// position with the lowest Hamming distance. Used by the screening module to carry person boxes
// (BoxTracker) and to match whole frames for the frame-to-frame evidence (TemporalScreening).
#include "yolo_slam/features/feature_frame.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace yolo_slam {
namespace features {

// Index of the keypoint of `frame` within radius_px of `p` (frame.keypoints coordinates) whose
// descriptor is closest to `desc` (32 bytes) and at most max_hamming bits away; -1 if none. Ties
// go to the lowest index (deterministic). `frame.descriptors` must have one row per keypoint.
int bestMatchNear(const FeatureFrame& frame, const cv::Point2f& p, const uint8_t* desc,
                  double radius_px, int max_hamming);

// The same query, many times on one frame: keypoints bucketed in square cells so a query only
// looks at the cells its radius touches (matching 1000 keypoints against 1000 drops from ~1M
// distance tests to a few tens of thousands). Results equal bestMatchNear's, ties included.
// Holds a pointer to `frame`, which must outlive it and not change.
class KeypointIndex {
 public:
  KeypointIndex(const FeatureFrame& frame, double cell_px);
  int bestMatchNear(const cv::Point2f& p, const uint8_t* desc, double radius_px,
                    int max_hamming) const;

 private:
  const FeatureFrame* frame_;
  float cell_ = 1.f, x0_ = 0.f, y0_ = 0.f;
  int cols_ = 0, rows_ = 0;
  std::vector<std::vector<int>> cells_;  // keypoint indices per cell, row-major
};

}  // namespace features
}  // namespace yolo_slam
