#include "yolo_slam/common/camera.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/option_checks.h"

#include <opencv2/calib3d.hpp>

#include <cmath>

namespace yolo_slam {

namespace {

// A required key, checked against its rule.
double requireChecked(const Config& cfg, const std::string& key, const Range& r) {
  const double v = cfg.requireDouble(key);
  checkOption(configName(cfg), key, v, r);
  return v;
}

}  // namespace

CameraModel CameraModel::load(const Config& cfg) {
  CameraModel c;
  c.width = readInt(cfg, "Camera.width", c.width, Range::closed(1, kMaxImageSide));
  c.height = readInt(cfg, "Camera.height", c.height, Range::closed(1, kMaxImageSide));
  c.fx = requireChecked(cfg, "Camera.fx", Range::positive());
  c.fy = requireChecked(cfg, "Camera.fy", Range::positive());
  // The principal point lies in the image; outside it the calibration belongs to another size.
  c.cx = requireChecked(cfg, "Camera.cx", Range::closed(0, c.width));
  c.cy = requireChecked(cfg, "Camera.cy", Range::closed(0, c.height));
  for (const auto& [key, v] : {std::make_pair("Camera.k1", &c.k1), std::make_pair("Camera.k2", &c.k2),
                               std::make_pair("Camera.p1", &c.p1), std::make_pair("Camera.p2", &c.p2),
                               std::make_pair("Camera.k3", &c.k3)})
    *v = readDouble(cfg, key, 0.0, Range::any());
  c.fps = readPositive(cfg, "Camera.fps", c.fps);
  c.bf = readPositive(cfg, "Camera.bf", c.bf);
  c.th_depth = readPositive(cfg, "ThDepth", c.th_depth);
  c.depth_map_factor = readPositive(cfg, "DepthMapFactor", c.depth_map_factor);
  c.max_depth = readPositive(cfg, "DepthMaxRange", c.max_depth);
  c.rgb_order = cfg.getInt("Camera.RGB", 1) != 0;
  return c;
}

cv::Mat CameraModel::K() const {
  return (cv::Mat_<double>(3, 3) << fx, 0, cx, 0, fy, cy, 0, 0, 1);
}

cv::Mat CameraModel::distCoeffs() const {
  return (cv::Mat_<double>(1, 5) << k1, k2, p1, p2, k3);
}

std::vector<cv::Point2f> CameraModel::undistort(const std::vector<cv::Point2f>& pts) const {
  if (!hasDistortion() || pts.empty()) return pts;
  std::vector<cv::Point2f> out;
  cv::undistortPoints(pts, out, K(), distCoeffs(), cv::noArray(), K());
  return out;
}

}  // namespace yolo_slam
