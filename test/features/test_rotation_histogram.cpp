// ORB-SLAM2's rotation consistency check, shared by the SLAM matchers and the vocabulary's BoW
// search.
#include "yolo_slam/features/rotation_histogram.h"

#include "yolo_slam/common/error.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace yolo_slam;
using features::RotationHistogram;

namespace {
// Votes `n` items turned by `rot` degrees, numbered from `first`.
void vote(RotationHistogram& h, float rot, size_t first, size_t n) {
  for (size_t i = first; i < first + n; ++i) h.add(50.0f + rot, 50.0f, i);
}

std::vector<size_t> sorted(std::vector<size_t> v) {
  std::sort(v.begin(), v.end());
  return v;
}
}  // namespace

TEST(RotationHistogram, BinsTheOrientationDifferenceAndWrapsAtAFullTurn) {
  const RotationHistogram h;
  EXPECT_EQ(h.bin(50.0f, 50.0f), 0);
  EXPECT_EQ(h.bin(62.0f, 50.0f), 1) << "12 degrees: one bin of 30 in a full turn";
  EXPECT_EQ(h.bin(50.0f, 62.0f), 29) << "-12 degrees is 348";
  EXPECT_EQ(h.bin(359.9f, 0.0f), 0) << "a full turn is no turn";
  EXPECT_EQ(RotationHistogram(4).bin(90.0f, 0.0f), 1);
}

TEST(RotationHistogram, KeepsTheThreeFullestBinsThatHoldATenthOfTheFullest) {
  RotationHistogram h;
  vote(h, 0.0f, 0, 20);     // the scene's rotation
  vote(h, 12.0f, 20, 3);    // the next bin, 3 >= 2: kept
  vote(h, 120.0f, 23, 2);   // 2 >= 2: kept, third
  vote(h, 240.0f, 25, 1);   // a fourth bin: dropped whatever its size
  EXPECT_EQ(sorted(h.outliers()), (std::vector<size_t>{25}));

  RotationHistogram sparse;
  vote(sparse, 0.0f, 0, 30);
  vote(sparse, 120.0f, 30, 2);  // 2 < 3: the second bin is dropped, and the third with it
  vote(sparse, 240.0f, 32, 1);
  EXPECT_EQ(sorted(sparse.outliers()), (std::vector<size_t>{30, 31, 32}));
}

TEST(RotationHistogram, OnATieTheLowerBinRanksFirst) {
  RotationHistogram h;
  for (int b = 0; b < 4; ++b) vote(h, 12.0f * b, 10 * b, 5);
  EXPECT_EQ(sorted(h.outliers()), (std::vector<size_t>{30, 31, 32, 33, 34}));
  EXPECT_TRUE(RotationHistogram().outliers().empty());
}

TEST(RotationHistogram, RefusesNoBins) {
  EXPECT_THROW(RotationHistogram(0), Error);
}
