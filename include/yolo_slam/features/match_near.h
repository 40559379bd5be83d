#pragma once
// Finds a remembered keypoint again in a new frame: the keypoint within a pixel radius of its old
// position with the lowest Hamming distance. Used by the screening module to carry person boxes
// (BoxTracker) and dynamic labels (LabelPropagator) from one frame to the next.
#include "yolo_slam/features/feature_frame.h"

#include <opencv2/core.hpp>

#include <cstdint>

namespace yolo_slam {
namespace features {

// Index of the keypoint of `frame` within radius_px of `p` (frame.keypoints coordinates) whose
// descriptor is closest to `desc` (32 bytes) and at most max_hamming bits away; -1 if none. Ties
// go to the lowest index (deterministic). `frame.descriptors` must have one row per keypoint.
int bestMatchNear(const FeatureFrame& frame, const cv::Point2f& p, const uint8_t* desc,
                  double radius_px, int max_hamming);

}  // namespace features
}  // namespace yolo_slam
