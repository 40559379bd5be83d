#include "yolo_slam/features/frame_builder.h"

#include "yolo_slam/common/error.h"

#include <opencv2/imgproc.hpp>

#include <cmath>

namespace yolo_slam {
namespace features {

cv::Mat toGray(const cv::Mat& image, bool rgb_order) {
  if (image.empty()) {
    throw Error("buildFeatureFrame: empty image; check that the RGB file was read");
  }
  if (image.depth() != CV_8U) {
    throw Error("buildFeatureFrame: image type " + cv::typeToString(image.type()) +
                " is not supported; pass 8-bit gray, BGR or RGB images");
  }
  cv::Mat gray;
  switch (image.channels()) {
    case 1:
      return image;
    case 3:
      cv::cvtColor(image, gray, rgb_order ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
      return gray;
    case 4:
      cv::cvtColor(image, gray, rgb_order ? cv::COLOR_RGBA2GRAY : cv::COLOR_BGRA2GRAY);
      return gray;
    default:
      throw Error("buildFeatureFrame: image with " + std::to_string(image.channels()) +
                  " channels is not supported; pass gray, BGR or RGB images");
  }
}

FeatureFrame buildFeatureFrame(const OrbExtractor& orb, const CameraModel& cam,
                               const cv::Mat& image, const cv::Mat& depth_m, double stamp) {
  cv::Mat gray = toGray(image, cam.rgb_order);
  if (!depth_m.empty()) {
    if (depth_m.type() != CV_32FC1) {
      throw Error("buildFeatureFrame: depth image type " + cv::typeToString(depth_m.type()) +
                  " is not CV_32FC1 metres; decode raw depth with io::decodeDepth first");
    }
    if (depth_m.size() != gray.size()) {
      throw Error("buildFeatureFrame: depth image is " + std::to_string(depth_m.cols) + "x" +
                  std::to_string(depth_m.rows) + " but the colour image is " +
                  std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
                  "; the depth must be registered to the colour image");
    }
  }

  FeatureFrame f;
  f.stamp = stamp;
  f.width = gray.cols;
  f.height = gray.rows;
  orb.extract(gray, f.keypoints, f.descriptors);
  const size_t n = f.keypoints.size();

  f.keypoints_un = f.keypoints;
  if (cam.hasDistortion() && n > 0) {
    std::vector<cv::Point2f> pts(n);
    for (size_t i = 0; i < n; ++i) pts[i] = f.keypoints[i].pt;
    std::vector<cv::Point2f> un = cam.undistort(pts);
    for (size_t i = 0; i < n; ++i) f.keypoints_un[i].pt = un[i];
  }

  f.depth.assign(n, -1.0f);
  f.right_u.assign(n, -1.0f);
  f.dynamic.assign(n, 0);
  if (!depth_m.empty()) {
    for (size_t i = 0; i < n; ++i) {
      // The depth image is registered to the raw (distorted) colour image.
      const int u = cvRound(f.keypoints[i].pt.x), v = cvRound(f.keypoints[i].pt.y);
      if (u < 0 || v < 0 || u >= depth_m.cols || v >= depth_m.rows) continue;
      const float d = depth_m.at<float>(v, u);
      if (!(d > 0.0f) || !std::isfinite(d)) continue;
      f.depth[i] = d;
      f.right_u[i] = static_cast<float>(f.keypoints_un[i].pt.x - cam.bf / d);
    }
  }
  return f;
}

}  // namespace features
}  // namespace yolo_slam
