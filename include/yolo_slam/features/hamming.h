#pragma once
// Hamming distance between 256-bit (32-byte) binary descriptors, as used by ORB matching.
#include <opencv2/core.hpp>

#include <cstdint>
#include <cstring>

namespace yolo_slam {
namespace features {

// Number of differing bits between two 32-byte descriptors (0..256). Works on 64-bit words with
// popcount; memcpy keeps it valid for unaligned rows of a cv::Mat.
inline int hammingDistance(const uint8_t* a, const uint8_t* b) {
  int dist = 0;
  for (int k = 0; k < 4; ++k) {
    uint64_t wa, wb;
    std::memcpy(&wa, a + 8 * k, 8);
    std::memcpy(&wb, b + 8 * k, 8);
    dist += __builtin_popcountll(wa ^ wb);
  }
  return dist;
}

// Convenience for single rows of N x 32 CV_8U descriptor matrices.
inline int hammingDistance(const cv::Mat& row_a, const cv::Mat& row_b) {
  return hammingDistance(row_a.ptr<uint8_t>(), row_b.ptr<uint8_t>());
}

}  // namespace features
}  // namespace yolo_slam
