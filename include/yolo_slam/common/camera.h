#pragma once
// Pinhole RGB-D camera with radial-tangential distortion, read from ORB-SLAM2-style keys.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <vector>

namespace yolo_slam {

class Config;

struct CameraModel {
  double fx = 535.4, fy = 539.2, cx = 320.1, cy = 247.6;   // TUM freiburg3 defaults
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;            // OpenCV distortion model
  int width = 640, height = 480;
  double fps = 30.0;
  // Stereo baseline times fx (ORB-SLAM2 "Camera.bf"); for RGB-D it defines the virtual right
  // coordinate u_r = u - bf / depth and, with ThDepth, the close/far split.
  double bf = 40.0;
  double th_depth = 40.0;            // ThDepth, in baselines: close if depth < th_depth * bf / fx
  double depth_map_factor = 5000.0;  // DepthMapFactor: raw 16-bit value / factor = metres
  // DepthMaxRange: readings farther than this (metres) are no reading; 10 m is the Kinect /
  // OpenNI limit, beyond which structured-light depth is noise.
  double max_depth = 10.0;
  bool rgb_order = true;             // Camera.RGB: 1 if images are RGB, 0 if BGR

  static constexpr int kMaxImageSide = 16384;  // pixels; larger is a typo, not a camera

  // Reads Camera.fx/fy/cx/cy/k1/k2/p1/p2/k3/width/height/fps/bf/RGB, ThDepth, DepthMapFactor,
  // DepthMaxRange. fx, fy, cx, cy are required; others default to the values above. Throws
  // yolo_slam::Error naming the file and key for a value that is NaN, infinite or absurd (the
  // principal point outside the image, a size beyond kMaxImageSide).
  static CameraModel load(const Config& cfg);

  bool hasDistortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }
  double baseline() const { return bf / fx; }
  double closeDepth() const { return th_depth * baseline(); }   // metres
  cv::Mat K() const;            // 3x3 CV_64F
  cv::Mat distCoeffs() const;   // 1x5 CV_64F (k1 k2 p1 p2 k3)

  // Pinhole projection of a point in camera coordinates (no distortion; points and keypoints
  // are undistorted before use).
  Eigen::Vector2d project(const Eigen::Vector3d& pc) const {
    return {fx * pc.x() / pc.z() + cx, fy * pc.y() / pc.z() + cy};
  }
  Eigen::Vector3d unproject(double u, double v, double depth) const {
    return {(u - cx) * depth / fx, (v - cy) * depth / fy, depth};
  }
  bool inImage(double u, double v) const { return u >= 0 && v >= 0 && u < width && v < height; }

  // Undistorts pixel coordinates (identity when there is no distortion).
  std::vector<cv::Point2f> undistort(const std::vector<cv::Point2f>& pts) const;
};

}  // namespace yolo_slam
