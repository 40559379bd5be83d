#include "yolo_slam/common/error.h"
#include "yolo_slam/io/depth.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sys/stat.h>
#include <unistd.h>

using namespace yolo_slam;

TEST(Depth, Decodes16BitWithFactor) {
  cv::Mat raw(2, 3, CV_16UC1);
  raw.at<uint16_t>(0, 0) = 0;
  raw.at<uint16_t>(0, 1) = 5000;
  raw.at<uint16_t>(0, 2) = 65535;
  raw.at<uint16_t>(1, 0) = 1;
  raw.at<uint16_t>(1, 1) = 7500;
  raw.at<uint16_t>(1, 2) = 12345;
  cv::Mat d = io::decodeDepth(raw, 5000.0, "raw");
  ASSERT_EQ(d.type(), CV_32FC1);
  EXPECT_FLOAT_EQ(d.at<float>(0, 0), 0.f);
  EXPECT_FLOAT_EQ(d.at<float>(0, 1), 1.f);
  EXPECT_EQ(d.at<float>(0, 2), 0.f) << "65535 is the saturated code, not 13.1 m";
  EXPECT_FLOAT_EQ(d.at<float>(1, 0), 1.f / 5000.f);
  EXPECT_FLOAT_EQ(d.at<float>(1, 1), 1.5f);
  EXPECT_FLOAT_EQ(d.at<float>(1, 2), 12345.f / 5000.f);
}

TEST(Depth, DecodesFloatMetresAndInvalidValues) {
  cv::Mat raw = (cv::Mat_<float>(1, 6) << 1.25f, NAN, INFINITY, -1.f, 0.f, 3.5f);
  cv::Mat d = io::decodeDepth(raw, 1.0, "f");
  ASSERT_EQ(d.type(), CV_32FC1);
  EXPECT_FLOAT_EQ(d.at<float>(0, 0), 1.25f);
  for (int c = 1; c < 5; ++c) EXPECT_EQ(d.at<float>(0, c), 0.f) << c;
  EXPECT_FLOAT_EQ(d.at<float>(0, 5), 3.5f);
  // A factor other than 1 is applied to float input too (e.g. float millimetres, factor 1000).
  cv::Mat mm = (cv::Mat_<float>(1, 1) << 1500.f);
  EXPECT_FLOAT_EQ(io::decodeDepth(mm, 1000.0, "mm").at<float>(0, 0), 1.5f);
  // Input is not modified.
  EXPECT_TRUE(std::isnan(raw.at<float>(0, 1)));
}

TEST(Depth, WrongTypeEmptyAndBadFactorNameTheImage) {
  for (const cv::Mat& bad : {cv::Mat(2, 2, CV_8UC1, cv::Scalar(1)), cv::Mat(2, 2, CV_16UC3),
                             cv::Mat(2, 2, CV_64FC1, cv::Scalar(1)), cv::Mat()}) {
    try {
      io::decodeDepth(bad, 5000.0, "frame_42.png");
      ADD_FAILURE() << "expected an error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("frame_42.png"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(io::decodeDepth(cv::Mat(2, 2, CV_16UC1, cv::Scalar(1)), 0.0, "x"), Error);
  EXPECT_THROW(io::decodeDepth(cv::Mat(2, 2, CV_16UC1, cv::Scalar(1)), NAN, "x"), Error);
}

TEST(Depth, LoadsPngAndRejectsMissingOrCorrupt) {
  std::string p = "/tmp/ys_io_depth_" + std::to_string(::getpid()) + ".png";
  cv::Mat raw(4, 4, CV_16UC1, cv::Scalar(10000));
  ASSERT_TRUE(cv::imwrite(p, raw));
  cv::Mat d = io::loadDepth(p, 5000.0);
  EXPECT_FLOAT_EQ(d.at<float>(3, 3), 2.f);
  std::ofstream(p, std::ios::trunc) << "not a png";
  EXPECT_THROW(io::loadDepth(p, 5000.0), Error);
  std::remove(p.c_str());
  try {
    io::loadDepth(p, 5000.0);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(p), std::string::npos);
  }
}

TEST(Depth, CountsReadingsAndRejectsBeyondTheRange) {
  cv::Mat raw = (cv::Mat_<uint16_t>(1, 5) << 0, 5000, 49999, 50001, io::kInvalidDepthCode);
  io::DepthCounts n;
  const cv::Mat d = io::decodeDepth(raw, 5000.0, "r", 10.0, &n);
  EXPECT_FLOAT_EQ(d.at<float>(0, 1), 1.f);
  EXPECT_FLOAT_EQ(d.at<float>(0, 2), 9.9998f);
  EXPECT_EQ(d.at<float>(0, 3), 0.f) << "10.0002 m is beyond the 10 m range";
  EXPECT_EQ(d.at<float>(0, 4), 0.f);
  EXPECT_EQ(n.valid, 2u);
  EXPECT_EQ(n.invalid, 1u);
  EXPECT_EQ(n.beyond_range, 1u);
  EXPECT_EQ(n.saturated, 1u);
  // Float metres obey the same range; a range <= 0 is refused with the name.
  const cv::Mat f = (cv::Mat_<float>(1, 2) << 4.f, 12.f);
  const cv::Mat df = io::decodeDepth(f, 1.0, "f", 10.0);
  EXPECT_FLOAT_EQ(df.at<float>(0, 0), 4.f);
  EXPECT_EQ(df.at<float>(0, 1), 0.f);
  try {
    io::decodeDepth(f, 1.0, "f.exr", 0.0);
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("f.exr: DepthMaxRange"), std::string::npos) << e.what();
  }
}

TEST(Depth, AllSaturatedOrAFolderIsAnErrorNamingTheFile) {
  const std::string dir = "/tmp/ys_io_depth_dir_" + std::to_string(::getpid());
  const std::string p = dir + ".png";
  ASSERT_TRUE(cv::imwrite(p, cv::Mat(4, 4, CV_16UC1, cv::Scalar(io::kInvalidDepthCode))));
  try {
    io::loadDepth(p, 5000.0);
    ADD_FAILURE() << "an all-65535 image is no depth";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(p + ": every reading is 65535"), std::string::npos) << e.what();
  }
  std::remove(p.c_str());
  ASSERT_EQ(::mkdir(dir.c_str(), 0755), 0);
  try {
    io::loadDepth(dir, 5000.0);
    ADD_FAILURE() << "a folder is not an image";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir + ": is a folder"), std::string::npos) << e.what();
  }
  ::rmdir(dir.c_str());
}
