#include "real_images.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/vocabulary/bow_matcher.h"
#include "yolo_slam/vocabulary/training_inputs.h"

#include <gtest/gtest.h>

using namespace yolo_slam;
using namespace yolo_slam::vocabulary;

namespace {
// One descriptor per entry, with the first n bits set (distance to all-zero = n).
cv::Mat bits(std::initializer_list<int> counts) {
  cv::Mat m(static_cast<int>(counts.size()), 32, CV_8U, cv::Scalar(0));
  int r = 0;
  for (int n : counts) {
    for (int b = 0; b < n; ++b) m.at<uint8_t>(r, b / 8) |= static_cast<uint8_t>(1u << (b % 8));
    ++r;
  }
  return m;
}
}  // namespace

TEST(BowMatcher, ThresholdRatioUniquenessAndNodes) {
  // Node 5: A0 vs B {8 bits, 20 bits}: 8 < 0.7 * 20 -> match (A0, B0).
  // Node 5: A1 (same as A0): B0 taken, B1 at 20 bits, no second -> match (A1, B1).
  // Node 7: A2 vs B2 at 128 bits -> above TH_LOW 50, no match.
  // Node 9 only on side A: never compared.
  const cv::Mat da = bits({0, 0, 0, 0});
  const cv::Mat db = bits({8, 20, 128});
  const FeatureVector fa{{5, {0, 1}}, {7, {2}}, {9, {3}}};
  const FeatureVector fb{{5, {0, 1}}, {7, {2}}};
  BowMatchOptions opt;
  opt.check_orientation = false;
  auto m = searchByBow({&fa, &da}, {&fb, &db}, opt);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].a, 0u);
  EXPECT_EQ(m[0].b, 0u);
  EXPECT_EQ(m[0].distance, 8);
  EXPECT_EQ(m[1].distance, 20);
  EXPECT_EQ(m[1].a, 1u);
  EXPECT_EQ(m[1].b, 1u);
  // Ratio test: second candidate nearly as close -> rejected.
  const cv::Mat db2 = bits({8, 10});  // 8 >= 0.7 * 10
  const FeatureVector fa2{{5, {0}}}, fb2{{5, {0, 1}}};
  EXPECT_TRUE(searchByBow({&fa2, &da}, {&fb2, &db2}, opt).empty());
  // Usable mask on B removes the ambiguity.
  const std::vector<uint8_t> usable{1, 0};
  EXPECT_EQ(searchByBow({&fa2, &da}, {&fb2, &db2, nullptr, &usable}, opt).size(), 1u);
  // Missing inputs are errors.
  EXPECT_THROW(searchByBow({&fa2, nullptr}, {&fb2, &db2}, opt), Error);
  opt.check_orientation = true;
  EXPECT_THROW(searchByBow({&fa2, &da}, {&fb2, &db2}, opt), Error);  // no keypoints
}

TEST(BowMatcher, OrientationCheckDropsInconsistentRotations) {
  // 12 matches rotating by ~40 degrees and one by 200: the odd one is dropped.
  cv::Mat da(13, 32, CV_8U), db(13, 32, CV_8U);
  FeatureVector fa, fb;
  std::vector<cv::KeyPoint> ka, kb;
  for (int i = 0; i < 13; ++i) {
    da.row(i).setTo(cv::Scalar(0));
    da.at<uint8_t>(i, 0) = static_cast<uint8_t>(i);
    da.row(i).copyTo(db.row(i));
    fa[static_cast<NodeId>(i)] = {static_cast<unsigned>(i)};
    fb[static_cast<NodeId>(i)] = {static_cast<unsigned>(i)};
    ka.emplace_back(cv::Point2f(0, 0), 31.f, 100.f);
    kb.emplace_back(cv::Point2f(0, 0), 31.f, i == 6 ? 260.f : 60.f + 0.5f * i);
  }
  auto m = searchByBow({&fa, &da, &ka}, {&fb, &db, &kb});
  EXPECT_EQ(m.size(), 12u);
  for (const auto& x : m) EXPECT_NE(x.a, 6u);
}

TEST(BowMatcher, MatchesRealImageUnderViewChange) {
  auto voc = vocab_test::shippedVocabulary();
  features::OrbExtractor orb{features::OrbOptions{}};
  const cv::Mat img = vocab_test::loadGray(vocab_test::heldOutImagePaths()[3]);  // building.jpg
  cv::Mat H;
  const cv::Mat warped = syntheticViewChange(img, 77, 0.7, &H);
  std::vector<cv::KeyPoint> k1, k2;
  cv::Mat d1, d2;
  orb.extract(img, k1, d1);
  orb.extract(warped, k2, d2);
  BowVector b1, b2;
  FeatureVector f1, f2;
  voc->transform(d1, b1, f1, 2);
  voc->transform(d2, b2, f2, 2);
  auto m = searchByBow({&f1, &d1, &k1}, {&f2, &d2, &k2});
  ASSERT_GT(m.size(), 100u);
  int good = 0;
  for (const auto& x : m) {
    std::vector<cv::Point2f> p{k1[x.a].pt}, q;
    cv::perspectiveTransform(p, q, H);
    good += cv::norm(q[0] - k2[x.b].pt) < 6.0 ? 1 : 0;
    EXPECT_LE(x.distance, 50);
  }
  EXPECT_GT(static_cast<double>(good) / m.size(), 0.8) << good << " of " << m.size();
}
