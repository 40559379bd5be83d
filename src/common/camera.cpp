#include "yolo_slam/common/camera.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"

#include <opencv2/calib3d.hpp>

#include <cmath>

namespace yolo_slam {

CameraModel CameraModel::load(const Config& cfg) {
  CameraModel c;
  c.fx = cfg.requireDouble("Camera.fx");
  c.fy = cfg.requireDouble("Camera.fy");
  c.cx = cfg.requireDouble("Camera.cx");
  c.cy = cfg.requireDouble("Camera.cy");
  c.k1 = cfg.getDouble("Camera.k1", 0.0);
  c.k2 = cfg.getDouble("Camera.k2", 0.0);
  c.p1 = cfg.getDouble("Camera.p1", 0.0);
  c.p2 = cfg.getDouble("Camera.p2", 0.0);
  c.k3 = cfg.getDouble("Camera.k3", 0.0);
  c.width = cfg.getInt("Camera.width", c.width);
  c.height = cfg.getInt("Camera.height", c.height);
  c.fps = cfg.getDouble("Camera.fps", c.fps);
  c.bf = cfg.getDouble("Camera.bf", c.bf);
  c.th_depth = cfg.getDouble("ThDepth", c.th_depth);
  c.depth_map_factor = cfg.getDouble("DepthMapFactor", c.depth_map_factor);
  c.rgb_order = cfg.getInt("Camera.RGB", 1) != 0;
  auto bad = [&](const char* key, const char* why) {
    throw Error(cfg.path() + ": key '" + key + "' " + why);
  };
  if (!(c.fx > 0) || !std::isfinite(c.fx)) bad("Camera.fx", "must be a positive number");
  if (!(c.fy > 0) || !std::isfinite(c.fy)) bad("Camera.fy", "must be a positive number");
  if (c.width <= 0 || c.height <= 0) bad("Camera.width", "and Camera.height must be positive");
  if (!(c.bf > 0)) bad("Camera.bf", "must be positive (baseline in metres times fx)");
  if (!(c.depth_map_factor > 0)) bad("DepthMapFactor", "must be positive (5000 for TUM PNG, 1 for metres)");
  if (!(c.fps > 0)) bad("Camera.fps", "must be positive");
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
