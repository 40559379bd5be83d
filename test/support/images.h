#pragma once
// Test images shared by the module tests.
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace yolo_slam {
namespace test_support {

// A 640x480 BGR image of smoothed noise: plenty of ORB corners, different per seed.
inline cv::Mat texturedImage(unsigned seed) {
  cv::Mat img(480, 640, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(img, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(img, img, cv::Size(5, 5), 1.5);
  return img;
}

}  // namespace test_support
}  // namespace yolo_slam
