#pragma once
// The static-scene mask of a keyframe for the dense map: every pixel but the people's. A person
// is what the screening's depth model says it is inside the box (screening::Screener: the
// nearest sizeable depth cluster, or Algorithm 1's consensus, of depths sampled in the dilated
// box), grown over connected depth inside the box, then widened by a margin in pixels (depth
// is smeared at a silhouette). docs/dense-map.md has the rule and its measurement.
#include "yolo_slam/detection/box.h"
#include "yolo_slam/screening/screener.h"

#include <opencv2/core.hpp>

namespace yolo_slam {
namespace mapping {

struct StaticMaskOptions {
  static constexpr int kDefaultMarginPx = 6;
  static constexpr int kDefaultSampleStridePx = 4;
  int margin_px = kDefaultMarginPx;                  // DenseMap.maskMargin
  int sample_stride_px = kDefaultSampleStridePx;     // DenseMap.maskSampleStride: depth samples
                                                     // of the box's depth model, every N pixels
};

// CV_8UC1 of the depth image's size: 255 static, 0 person. depth_m: CV_32FC1 metres, <= 0 or
// NaN = no depth. Which pixels a box removes follows the screening mode: off and geometry (no
// boxes) remove nothing, detect the whole dilated box, detect+geometry the depth-refined person.
// Throws yolo_slam::Error when depth_m is not CV_32FC1.
cv::Mat staticMask(const cv::Mat& depth_m, const detection::Boxes& boxes,
                   const screening::Screener& screener, const StaticMaskOptions& options);

}  // namespace mapping
}  // namespace yolo_slam
