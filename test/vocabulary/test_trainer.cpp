#include "yolo_slam/common/error.h"
#include "yolo_slam/vocabulary/trainer.h"

#include <gtest/gtest.h>

#include <random>

using namespace yolo_slam;
using namespace yolo_slam::vocabulary;

namespace {
std::vector<cv::Mat> randomImages(int n, int per, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<cv::Mat> out;
  for (int i = 0; i < n; ++i) {
    cv::Mat m(per, 32, CV_8U);
    for (int r = 0; r < per; ++r)
      for (int b = 0; b < 32; ++b) m.at<uint8_t>(r, b) = static_cast<uint8_t>(rng());
    out.push_back(m);
  }
  return out;
}
}  // namespace

TEST(Trainer, DeterministicForASeed) {
  auto imgs = randomImages(20, 100, 3);
  TrainerOptions opt;
  opt.k = 5;
  opt.levels = 3;
  opt.seed = 11;
  auto a = trainVocabulary(imgs, opt);
  auto b = trainVocabulary(imgs, opt);
  EXPECT_TRUE(a->identical(*b));
  opt.seed = 12;
  auto c = trainVocabulary(imgs, opt);
  EXPECT_FALSE(a->identical(*c));
}

TEST(Trainer, TreeShapeWeightsAndReport) {
  auto imgs = randomImages(40, 100, 4);  // 4000 descriptors, 125 leaves possible
  TrainerOptions opt;
  opt.k = 5;
  opt.levels = 3;
  TrainingReport rep;
  size_t last = 0, calls = 0;
  auto v = trainVocabulary(imgs, opt, &rep, [&](size_t done, size_t total) {
    EXPECT_GE(done, last);
    EXPECT_LE(done, total);
    last = done;
    ++calls;
  });
  EXPECT_GT(calls, 0u);
  EXPECT_EQ(last, 4000u * 3u);
  EXPECT_EQ(rep.descriptors, 4000u);
  EXPECT_EQ(rep.images, 40u);
  EXPECT_EQ(rep.words, v->size());
  EXPECT_DOUBLE_EQ(rep.capacity, 125.0);
  // Uniform random data fills every leaf of a 5^3 tree.
  EXPECT_EQ(v->size(), 125u);
  EXPECT_GE(rep.words_hit, 120u);
  for (WordId w = 0; w < v->size(); ++w) {
    EXPECT_EQ(v->nodeLevel(v->wordNode(w)), 3);
    // idf = log(40 / n_i) with 1 <= n_i <= 40 images
    EXPECT_GE(v->wordWeight(w), 0.0);
    EXPECT_LE(v->wordWeight(w), std::log(40.0) + 1e-12);
  }
}

TEST(Trainer, SmallInputsMakeShallowLeavesAndBadOptionsThrow) {
  auto imgs = randomImages(1, 8, 5);
  TrainerOptions opt;
  opt.k = 10;
  EXPECT_THROW(trainVocabulary(imgs, opt), Error);  // 8 < k descriptors
  opt.k = 4;
  auto v = trainVocabulary(imgs, opt);  // 8 descriptors: a few levels, all leaves used
  EXPECT_LE(v->size(), 8u);
  EXPECT_GE(v->size(), 2u);
  opt.k = 1;
  EXPECT_THROW(trainVocabulary(imgs, opt), Error);
  cv::Mat wrong(4, 16, CV_8U, cv::Scalar(0));
  opt.k = 2;
  EXPECT_THROW(trainVocabulary({wrong}, opt), Error);
}
