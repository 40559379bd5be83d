#pragma once
// The keypoints of one RGB-D frame as they travel from extraction through screening into
// tracking (and, in ROS, across the Screening -> Slam nodelet topic). Plain value type.
#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace yolo_slam {
namespace features {

// Hamming distance bounds (of 256 bits) of an ORB descriptor match, ORB-SLAM2's ORBmatcher
// TH_LOW (a confident match: BoW, triangulation, fusion, and frame-to-frame matching in
// screening) and TH_HIGH (projection searches).
constexpr int kOrbHammingLow = 50;
constexpr int kOrbHammingHigh = 100;

struct FeatureFrame {
  double stamp = 0.0;
  int width = 0, height = 0;                 // image size in pixels
  std::vector<cv::KeyPoint> keypoints;       // as detected (distorted image coordinates)
  std::vector<cv::KeyPoint> keypoints_un;    // undistorted (equal to keypoints without distortion)
  cv::Mat descriptors;                       // N x 32 CV_8U, rotated BRIEF (256 bits)
  std::vector<float> depth;                  // metres per keypoint; <= 0 means no valid depth
  // Virtual right coordinate u_un - bf/d; -1 without depth. It can also be < 0 for a valid,
  // very close depth near the left border: such keypoints get the monocular residual, as in
  // ORB-SLAM2. Test depth > 0, not right_u, for "has depth".
  std::vector<float> right_u;
  std::vector<uint8_t> dynamic;              // 1 = screened as dynamic (never used by SLAM)
  // Frame-to-frame motion test per keypoint (screening/temporal.h): 1 where a static point
  // would be, 0 moved, -1 untested; empty when the test did not run. Tracking marks a map point
  // dynamic only on evidence that is not "static-consistent".
  std::vector<int8_t> motion;
  // 1 = inside a person box and screened static there (background seen past a person, or a
  // person the screening could not separate from it); empty when no box screening ran.
  std::vector<uint8_t> boxed;

  size_t size() const { return keypoints.size(); }
  size_t countDynamic() const {
    size_t n = 0;
    for (uint8_t d : dynamic) n += d ? 1 : 0;
    return n;
  }
};

}  // namespace features
}  // namespace yolo_slam
