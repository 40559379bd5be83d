#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/features/hamming.h"
#include "yolo_slam/features/orb_extractor.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <random>

using namespace yolo_slam;
using namespace yolo_slam::features;

namespace {

cv::Mat loadTumGray() {
  const std::string path = joinPath(
      sharedDir(), "data/tum/rgbd_dataset_freiburg3_walking_xyz/rgb/1341846316.570121.png");
  cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (img.empty()) throw Error(path + ": missing; set YOLO_SLAM_SHARED to the shared folder");
  return img;
}

}  // namespace

TEST(Hamming, MatchesBitCount) {
  std::mt19937 gen(3);
  for (int trial = 0; trial < 100; ++trial) {
    uint8_t a[32], b[32];
    int expected = 0;
    for (int i = 0; i < 32; ++i) {
      a[i] = static_cast<uint8_t>(gen());
      b[i] = static_cast<uint8_t>(gen());
      for (int bit = 0; bit < 8; ++bit) expected += ((a[i] ^ b[i]) >> bit) & 1;
    }
    EXPECT_EQ(hammingDistance(a, b), expected);
    EXPECT_EQ(hammingDistance(a, a), 0);
  }
}

TEST(OrbOptions, LoadsKeysAndRejectsBadValues) {
  Config c = Config::fromString(
      "ORBextractor.nFeatures: 1500\nORBextractor.scaleFactor: 1.25\nORBextractor.nLevels: 6\n"
      "ORBextractor.iniThFAST: 25\nORBextractor.minThFAST: 9\n", "orb.yaml");
  OrbOptions o = OrbOptions::load(c);
  EXPECT_EQ(o.n_features, 1500);
  EXPECT_DOUBLE_EQ(o.scale_factor, 1.25);
  EXPECT_EQ(o.n_levels, 6);
  EXPECT_EQ(o.ini_th_fast, 25);
  EXPECT_EQ(o.min_th_fast, 9);
  OrbOptions d = OrbOptions::load(Config());
  EXPECT_EQ(d.n_features, 1000);
  EXPECT_EQ(d.n_levels, 8);
  try {
    OrbOptions::load(Config::fromString("ORBextractor.scaleFactor: 0.8\n", "bad.yaml"));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("ORBextractor.scaleFactor"), std::string::npos);
  }
  EXPECT_THROW(OrbOptions::load(Config::fromString("ORBextractor.nFeatures: 0\n")), Error);
  EXPECT_THROW(OrbOptions::load(Config::fromString("ORBextractor.minThFAST: 30\n")), Error);
}

TEST(OrbExtractor, LevelBudgetAndScales) {
  OrbExtractor orb(OrbOptions{});
  const auto& per = orb.featuresPerLevel();
  ASSERT_EQ(per.size(), 8u);
  int sum = 0;
  for (int n : per) sum += n;
  EXPECT_EQ(sum, 1000);
  // ORB-SLAM2: 1000 * (1 - 1/1.2) / (1 - 1.2^-8) = 217.0 on level 0, then / 1.2 per level.
  EXPECT_EQ(per[0], 217);
  EXPECT_EQ(per[1], 181);
  EXPECT_NEAR(orb.scaleFactors()[7], std::pow(1.2, 7), 1e-12);
  EXPECT_NEAR(orb.levelSigma2()[2] * orb.invLevelSigma2()[2], 1.0, 1e-12);
  EXPECT_NEAR(orb.levelSigma2()[2], std::pow(1.2, 4), 1e-12);
}

TEST(OrbExtractor, PatternStaysInsideRotatedPatch) {
  const auto& p = OrbExtractor::briefPattern();
  ASSERT_EQ(p.size(), 512u);
  int far = 0;
  for (size_t i = 0; i < p.size(); i += 2) {
    EXPECT_NE(p[i], p[i + 1]);
    for (int k = 0; k < 2; ++k) {
      EXPECT_LE(p[i + k].x * p[i + k].x + p[i + k].y * p[i + k].y, 15 * 15);
      far += std::abs(p[i + k].x) > 6 ? 1 : 0;
    }
  }
  // Gaussian with sigma 6.2: about a third of the coordinates lie beyond 6 px.
  EXPECT_GT(far, 100);
  EXPECT_LT(far, 300);
}

TEST(OrbExtractor, SpreadsKeypointsOverRealImage) {
  cv::Mat gray = loadTumGray();
  OrbExtractor orb(OrbOptions{});
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  orb.extract(gray, kps, desc);
  EXPECT_LE(kps.size(), 1000u);
  EXPECT_GE(kps.size(), 900u);
  ASSERT_EQ(desc.rows, static_cast<int>(kps.size()));
  EXPECT_EQ(desc.cols, 32);
  EXPECT_EQ(desc.type(), CV_8U);

  int grid[4][4] = {};
  std::vector<int> per_level(8, 0);
  for (const cv::KeyPoint& kp : kps) {
    ASSERT_GE(kp.octave, 0);
    ASSERT_LT(kp.octave, 8);
    per_level[kp.octave]++;
    EXPECT_NEAR(kp.size, 31.0 * orb.scaleFactors()[kp.octave], 1e-3);
    EXPECT_GE(kp.angle, 0.0f);
    EXPECT_LT(kp.angle, 360.0f);
    ASSERT_GE(kp.pt.x, 0);
    ASSERT_GE(kp.pt.y, 0);
    ASSERT_LT(kp.pt.x, gray.cols);
    ASSERT_LT(kp.pt.y, gray.rows);
    grid[std::min(3, static_cast<int>(kp.pt.y * 4 / gray.rows))]
        [std::min(3, static_cast<int>(kp.pt.x * 4 / gray.cols))]++;
  }
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) EXPECT_GT(grid[r][c], 0) << "empty cell " << r << "," << c;
  }
  for (int l = 0; l < 8; ++l) {
    EXPECT_LE(per_level[l], orb.featuresPerLevel()[l]);
    EXPECT_GT(per_level[l], 0) << "level " << l;
  }
  // No cell of a 4x4 grid should hold a large majority: the quadtree spreads keypoints.
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) EXPECT_LT(grid[r][c], static_cast<int>(kps.size()) / 4);
  }
}

TEST(OrbExtractor, IsDeterministic) {
  cv::Mat gray = loadTumGray();
  OrbExtractor a(OrbOptions{}), b(OrbOptions{});
  std::vector<cv::KeyPoint> ka, kb;
  cv::Mat da, db;
  a.extract(gray, ka, da);
  b.extract(gray.clone(), kb, db);
  ASSERT_EQ(ka.size(), kb.size());
  for (size_t i = 0; i < ka.size(); ++i) {
    EXPECT_EQ(ka[i].pt, kb[i].pt);
    EXPECT_EQ(ka[i].angle, kb[i].angle);
    EXPECT_EQ(ka[i].octave, kb[i].octave);
  }
  EXPECT_EQ(cv::norm(da, db, cv::NORM_L1), 0.0);
}

namespace {

void expectSameFeatures(const cv::Mat& gray, OrbOptions opt) {
  OrbOptions one_opt = opt, two_opt = opt;
  one_opt.threads = 1;
  two_opt.threads = 2;
  OrbExtractor one(one_opt), two(two_opt);
  std::vector<cv::KeyPoint> k1, k2;
  cv::Mat d1, d2;
  one.extract(gray, k1, d1);
  for (int run = 0; run < 3; ++run) {
    two.extract(gray, k2, d2);
    ASSERT_EQ(k1.size(), k2.size());
    for (size_t i = 0; i < k1.size(); ++i) {
      EXPECT_EQ(k1[i].pt, k2[i].pt);
      EXPECT_EQ(k1[i].angle, k2[i].angle);
      EXPECT_EQ(k1[i].octave, k2[i].octave);
      EXPECT_EQ(k1[i].response, k2[i].response);
    }
    EXPECT_EQ(cv::norm(d1, d2, cv::NORM_L1), 0.0);
  }
}

}  // namespace

// The two threads share the levels in whatever order they finish: same keypoints, same order,
// same descriptors as one thread; also when the image is too small for the upper levels.
TEST(OrbExtractor, TwoThreadsGiveTheSameFeaturesAsOne) {
  cv::Mat gray = loadTumGray();
  expectSameFeatures(gray, OrbOptions{});
  OrbOptions many_levels;
  many_levels.n_levels = 14;
  expectSameFeatures(gray, many_levels);
  expectSameFeatures(gray(cv::Rect(200, 150, 120, 90)).clone(), OrbOptions{});
}

TEST(OrbExtractor, BadAndDegenerateInputs) {
  OrbExtractor orb(OrbOptions{});
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  EXPECT_THROW(orb.extract(cv::Mat(), kps, desc), Error);
  EXPECT_THROW(orb.extract(cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0)), kps, desc), Error);
  EXPECT_THROW(orb.extract(cv::Mat(480, 640, CV_32F, cv::Scalar::all(0)), kps, desc), Error);
  // All-black and saturated frames: nothing to find, no crash.
  orb.extract(cv::Mat(480, 640, CV_8UC1, cv::Scalar::all(0)), kps, desc);
  EXPECT_TRUE(kps.empty());
  EXPECT_EQ(desc.rows, 0);
  orb.extract(cv::Mat(480, 640, CV_8UC1, cv::Scalar::all(255)), kps, desc);
  EXPECT_TRUE(kps.empty());
  // Images too small for some or all levels.
  cv::Mat noise(30, 30, CV_8UC1);
  cv::randu(noise, 0, 255);
  orb.extract(noise, kps, desc);
  EXPECT_TRUE(kps.empty());
  cv::Mat small(80, 100, CV_8UC1);
  cv::randu(small, 0, 255);
  orb.extract(small, kps, desc);
  EXPECT_EQ(desc.rows, static_cast<int>(kps.size()));
  for (const auto& kp : kps) {
    EXPECT_GE(kp.pt.x, 0);
    EXPECT_LT(kp.pt.x, small.cols);
  }
}

// Descriptors of a real photo rotated by a large angle still match the right keypoints: the
// intensity-centroid angle follows the rotation and steers the BRIEF pattern.
TEST(OrbExtractor, DescriptorsAreRotationInvariant) {
  cv::Mat gray = loadTumGray();
  OrbExtractor orb(OrbOptions{});
  std::vector<cv::KeyPoint> k0;
  cv::Mat d0;
  orb.extract(gray, k0, d0);

  for (double angle_deg : {30.0, 90.0}) {
    // Rotate about the centre into a canvas big enough to hold the whole image.
    const cv::Point2f c(gray.cols * 0.5f, gray.rows * 0.5f);
    cv::Mat R = cv::getRotationMatrix2D(c, angle_deg, 1.0);
    const int side = static_cast<int>(std::ceil(std::hypot(gray.cols, gray.rows)));
    R.at<double>(0, 2) += side * 0.5 - c.x;
    R.at<double>(1, 2) += side * 0.5 - c.y;
    cv::Mat rotated;
    cv::warpAffine(gray, rotated, R, cv::Size(side, side), cv::INTER_LINEAR,
                   cv::BORDER_CONSTANT, cv::Scalar(0));
    std::vector<cv::KeyPoint> k1;
    cv::Mat d1;
    orb.extract(rotated, k1, d1);
    ASSERT_GT(k1.size(), 500u);

    int matched = 0, correct = 0, angle_ok = 0;
    for (int i = 0; i < d0.rows; ++i) {
      int best = 257, second = 257, best_j = -1;
      for (int j = 0; j < d1.rows; ++j) {
        int d = hammingDistance(d0.ptr<uint8_t>(i), d1.ptr<uint8_t>(j));
        if (d < best) {
          second = best;
          best = d;
          best_j = j;
        } else if (d < second) {
          second = d;
        }
      }
      if (best > 50 || best >= 0.8 * second) continue;
      ++matched;
      const cv::Point2f& p = k0[i].pt;
      cv::Point2f expected(static_cast<float>(R.at<double>(0, 0) * p.x + R.at<double>(0, 1) * p.y + R.at<double>(0, 2)),
                           static_cast<float>(R.at<double>(1, 0) * p.x + R.at<double>(1, 1) * p.y + R.at<double>(1, 2)));
      const double tol = 3.0 * orb.scaleFactors()[k0[i].octave];
      if (cv::norm(expected - k1[best_j].pt) <= tol) {
        ++correct;
        // getRotationMatrix2D rotates counter-clockwise on screen: image angles (y down) drop.
        double da = std::fmod(k0[i].angle - angle_deg - k1[best_j].angle + 720.0, 360.0);
        if (std::min(da, 360.0 - da) < 15.0) ++angle_ok;
      }
    }
    std::printf("rot %.0f: matched %d correct %d angle_ok %d\n", angle_deg, matched, correct, angle_ok);
    EXPECT_GT(correct, 150) << "rotation " << angle_deg;
    EXPECT_GT(correct, 0.8 * matched) << "rotation " << angle_deg << ": " << correct << "/" << matched;
    EXPECT_GT(angle_ok, 0.8 * correct) << "rotation " << angle_deg;
  }
}
