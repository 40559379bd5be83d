#pragma once
// Hamming distance between 256-bit ORB descriptors (32 bytes), popcount on 64-bit words.
#include <cstdint>
#include <cstring>

namespace yolo_slam {
namespace vocabulary {

constexpr int kDescriptorBytes = 32;

inline int descriptorDistance(const uint8_t* a, const uint8_t* b) {
  int d = 0;
  for (int i = 0; i < kDescriptorBytes; i += 8) {
    uint64_t x, y;  // memcpy: rows of a cv::Mat need not be 8-byte aligned
    std::memcpy(&x, a + i, 8);
    std::memcpy(&y, b + i, 8);
    d += __builtin_popcountll(x ^ y);
  }
  return d;
}

}  // namespace vocabulary
}  // namespace yolo_slam
