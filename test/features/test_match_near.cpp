#include "yolo_slam/features/match_near.h"

#include <gtest/gtest.h>

#include <random>

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

TEST(MatchNear, IndexAnswersExactlyLikeTheLinearSearch) {
  // Keypoints on a coarse lattice with few distinct descriptors: many candidates, many ties.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> ux(-5.f, 645.f), uy(-5.f, 485.f);
  cv::Mat palette(4, 32, CV_8U);
  cv::RNG(6).fill(palette, cv::RNG::UNIFORM, 0, 256);
  features::FeatureFrame f;
  for (int i = 0; i < 800; ++i) {
    f.keypoints.emplace_back(cv::Point2f(std::round(ux(rng) / 4) * 4, std::round(uy(rng) / 4) * 4), 31.f);
    f.descriptors.push_back(palette.row(i % 4));
  }
  for (double cell : {7.0, 30.0, 200.0}) {
    const features::KeypointIndex index(f, cell);
    for (int q = 0; q < 300; ++q) {
      const cv::Point2f p(ux(rng), uy(rng));
      const uint8_t* d = palette.ptr<uint8_t>(q % 4);
      for (double r : {3.0, 30.0, 90.0})
        ASSERT_EQ(index.bestMatchNear(p, d, r, 50), features::bestMatchNear(f, p, d, r, 50))
            << "cell " << cell << " radius " << r << " query (" << p.x << ", " << p.y << ")";
    }
  }
  features::FeatureFrame empty;
  EXPECT_EQ(features::KeypointIndex(empty, 30).bestMatchNear({1, 1}, palette.ptr<uint8_t>(0), 30, 256), -1);
}
