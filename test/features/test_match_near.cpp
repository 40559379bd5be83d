#include "yolo_slam/features/match_near.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

namespace {
// Keypoints at `pts` with descriptors that differ from `base` in the given number of bits.
features::FeatureFrame frameWith(const std::vector<cv::Point2f>& pts, const cv::Mat& base,
                                 const std::vector<int>& flipped_bits) {
  features::FeatureFrame f;
  for (size_t i = 0; i < pts.size(); ++i) {
    f.keypoints.emplace_back(pts[i], 31.f);
    cv::Mat d = base.clone();
    for (int b = 0; b < flipped_bits[i]; ++b) d.at<uint8_t>(0, b / 8) ^= static_cast<uint8_t>(1u << (b % 8));
    f.descriptors.push_back(d);
  }
  return f;
}
}  // namespace

TEST(MatchNear, PicksTheClosestDescriptorInsideTheRadius) {
  cv::Mat base(1, 32, CV_8U);
  cv::RNG(3).fill(base, cv::RNG::UNIFORM, 0, 256);
  // 0: 5 bits away, 10 px; 1: 2 bits away but 50 px away; 2: 3 bits away, 20 px.
  const auto f = frameWith({{110, 100}, {150, 100}, {100, 120}}, base, {5, 2, 3});
  EXPECT_EQ(features::bestMatchNear(f, {100, 100}, base.ptr<uint8_t>(), 30, 50), 2);
  EXPECT_EQ(features::bestMatchNear(f, {100, 100}, base.ptr<uint8_t>(), 60, 50), 1);
}

TEST(MatchNear, RespectsTheHammingBoundAndBreaksTiesByIndex) {
  cv::Mat base(1, 32, CV_8U);
  cv::RNG(4).fill(base, cv::RNG::UNIFORM, 0, 256);
  const auto f = frameWith({{100, 100}, {101, 100}}, base, {40, 40});
  EXPECT_EQ(features::bestMatchNear(f, {100, 100}, base.ptr<uint8_t>(), 10, 39), -1);
  EXPECT_EQ(features::bestMatchNear(f, {100, 100}, base.ptr<uint8_t>(), 10, 40), 0);
}

TEST(MatchNear, NoMatchWithoutDescriptorsForEveryKeypoint) {
  cv::Mat base(1, 32, CV_8U, cv::Scalar(0));
  features::FeatureFrame f;
  f.keypoints.emplace_back(cv::Point2f(10, 10), 31.f);  // descriptors missing
  EXPECT_EQ(features::bestMatchNear(f, {10, 10}, base.ptr<uint8_t>(), 10, 256), -1);
}
