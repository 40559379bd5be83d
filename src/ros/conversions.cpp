#include "yolo_slam/ros/conversions.h"

#include <cv_bridge/cv_bridge.h>
#include <image_geometry/pinhole_camera_model.h>
#include <opencv2/imgproc.hpp>
#include <sensor_msgs/image_encodings.h>
#include <tf2_eigen/tf2_eigen.h>

#include <cmath>
#include <cstring>

#include "yolo_slam/common/error.h"
#include "yolo_slam/io/depth.h"

namespace yolo_slam {
namespace ros1 {

namespace enc = sensor_msgs::image_encodings;

BoundingBox toMsg(const detection::Box& box) {
  BoundingBox m;
  m.class_id = box.class_id;
  m.label = box.label;
  m.score = box.score;
  m.x = box.rect.x;
  m.y = box.rect.y;
  m.width = box.rect.width;
  m.height = box.rect.height;
  return m;
}

detection::Box fromMsg(const BoundingBox& m) {
  detection::Box b;
  b.class_id = m.class_id;
  b.label = m.label;
  b.score = m.score;
  b.rect = cv::Rect2f(m.x, m.y, m.width, m.height);
  return b;
}

void toMsg(const detection::Boxes& boxes, BoundingBoxes& msg) {
  msg.boxes.clear();
  msg.boxes.reserve(boxes.size());
  for (const auto& b : boxes) msg.boxes.push_back(toMsg(b));
}

detection::Boxes boxesFromMsg(const std::vector<BoundingBox>& msgs) {
  detection::Boxes out;
  out.reserve(msgs.size());
  for (const auto& m : msgs) out.push_back(fromMsg(m));
  return out;
}

void toMsg(const features::FeatureFrame& f, const detection::Boxes& boxes, KeypointFrame& msg) {
  const size_t n = f.keypoints.size();
  msg.width = static_cast<uint32_t>(f.width);
  msg.height = static_cast<uint32_t>(f.height);
  msg.keypoints.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const cv::KeyPoint& k = f.keypoints[i];
    auto& m = msg.keypoints[i];
    m.x = k.pt.x;
    m.y = k.pt.y;
    m.octave = k.octave;
    m.angle = k.angle;
    m.response = k.response;
  }
  msg.descriptors.resize(n * 32);
  if (n > 0) {
    if (f.descriptors.rows != static_cast<int>(n) || f.descriptors.cols != 32 ||
        f.descriptors.type() != CV_8U)
      throw Error("KeypointFrame: descriptors must be " + std::to_string(n) +
                  " x 32 CV_8U, got " + std::to_string(f.descriptors.rows) + " x " +
                  std::to_string(f.descriptors.cols));
    for (size_t i = 0; i < n; ++i)
      std::memcpy(&msg.descriptors[i * 32], f.descriptors.ptr<uint8_t>(static_cast<int>(i)), 32);
  }
  msg.depth.assign(f.depth.begin(), f.depth.end());
  msg.depth.resize(n, 0.f);
  msg.dynamic.assign(f.dynamic.begin(), f.dynamic.end());
  msg.dynamic.resize(n, 0);
  if (f.motion.size() == n) msg.motion.assign(f.motion.begin(), f.motion.end());
  else msg.motion.clear();
  if (f.boxed.size() == n) msg.boxed.assign(f.boxed.begin(), f.boxed.end());
  else msg.boxed.clear();
  msg.boxes.clear();
  msg.boxes.reserve(boxes.size());
  for (const auto& b : boxes) msg.boxes.push_back(toMsg(b));
}

features::FeatureFrame fromMsg(const KeypointFrame& msg, const CameraModel& cam) {
  const size_t n = msg.keypoints.size();
  if (msg.descriptors.size() != n * 32 || msg.depth.size() != n || msg.dynamic.size() != n)
    throw Error("KeypointFrame: inconsistent arrays (" + std::to_string(n) + " keypoints, " +
                std::to_string(msg.descriptors.size()) + " descriptor bytes, " +
                std::to_string(msg.depth.size()) + " depths, " +
                std::to_string(msg.dynamic.size()) +
                " flags); expected N, 32*N, N, N. Publish frames with yolo_slam/Screening");
  if (msg.width == 0 || msg.height == 0)
    throw Error("KeypointFrame: width/height are 0; the image size is needed for tracking");
  features::FeatureFrame f;
  f.stamp = msg.header.stamp.toSec();
  f.width = static_cast<int>(msg.width);
  f.height = static_cast<int>(msg.height);
  f.keypoints.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const auto& m = msg.keypoints[i];
    cv::KeyPoint& k = f.keypoints[i];
    k.pt = cv::Point2f(m.x, m.y);
    k.octave = m.octave;
    k.angle = m.angle;
    k.response = m.response;
    // ORB patch size at the keypoint's level, as the extractor sets it (31 * scale).
    k.size = 31.f;
  }
  if (cam.hasDistortion() && n > 0) {
    std::vector<cv::Point2f> pts(n);
    for (size_t i = 0; i < n; ++i) pts[i] = f.keypoints[i].pt;
    std::vector<cv::Point2f> un = cam.undistort(pts);
    f.keypoints_un = f.keypoints;
    for (size_t i = 0; i < n; ++i) f.keypoints_un[i].pt = un[i];
  } else {
    f.keypoints_un = f.keypoints;
  }
  f.descriptors = cv::Mat(static_cast<int>(n), 32, CV_8U);
  if (n > 0) std::memcpy(f.descriptors.data, msg.descriptors.data(), n * 32);
  f.depth.assign(msg.depth.begin(), msg.depth.end());
  f.dynamic.assign(msg.dynamic.begin(), msg.dynamic.end());
  if (msg.motion.size() == n) f.motion.assign(msg.motion.begin(), msg.motion.end());
  if (msg.boxed.size() == n) f.boxed.assign(msg.boxed.begin(), msg.boxed.end());
  f.right_u.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const float d = f.depth[i];
    f.right_u[i] = d > 0 ? static_cast<float>(f.keypoints_un[i].pt.x - cam.bf / d) : -1.f;
  }
  return f;
}

namespace {

void checkImage(const sensor_msgs::Image& msg, const std::string& topic, int channels,
                int bytes_per_channel) {
  if (msg.width == 0 || msg.height == 0 || msg.data.empty())
    throw Error("empty image on " + topic + " (" + std::to_string(msg.width) + "x" +
                std::to_string(msg.height) + ", " + std::to_string(msg.data.size()) +
                " bytes); check the camera driver or bag");
  const size_t row = static_cast<size_t>(msg.width) * channels * bytes_per_channel;
  if (msg.step < row || msg.data.size() < static_cast<size_t>(msg.step) * msg.height)
    throw Error("image on " + topic + " has inconsistent step/data size (step " +
                std::to_string(msg.step) + ", " + std::to_string(msg.data.size()) +
                " bytes for " + std::to_string(msg.width) + "x" + std::to_string(msg.height) +
                " " + msg.encoding + ")");
}

// cv_bridge's view of the message's pixels (no copy). cv_bridge does not compare step and data
// size with the image size: checkImage above does, before any pixel is read.
cv::Mat view(const sensor_msgs::Image& msg) { return cv_bridge::toCvShare(msg, nullptr)->image; }

}  // namespace

cv::Mat imageView(const sensor_msgs::Image& msg, const std::string& topic, bool& is_rgb) {
  const std::string& e = msg.encoding;
  if (e == enc::RGB8 || e == enc::BGR8) {
    checkImage(msg, topic, 3, 1);
    is_rgb = e == enc::RGB8;
    return view(msg);
  }
  is_rgb = false;
  return imageToBgr(msg, topic);
}

cv::Mat imageToBgr(const sensor_msgs::Image& msg, const std::string& topic) {
  const std::string& e = msg.encoding;
  int channels = 0;
  if (e == enc::RGB8 || e == enc::BGR8) channels = 3;
  else if (e == enc::RGBA8 || e == enc::BGRA8) channels = 4;
  else if (e == enc::MONO8) channels = 1;
  else
    throw Error("unsupported colour encoding '" + e + "' on " + topic +
                "; expected rgb8, bgr8, rgba8, bgra8 or mono8 (is a depth topic remapped "
                "to the colour input?)");
  checkImage(msg, topic, channels, 1);
  return cv_bridge::toCvCopy(msg, enc::BGR8)->image;
}

cv::Mat depthToMetres(const sensor_msgs::Image& msg, const std::string& topic, double factor_16u) {
  const std::string& e = msg.encoding;
  if (e == enc::TYPE_16UC1 || e == enc::MONO16) {
    checkImage(msg, topic, 1, 2);
    return io::decodeDepth(view(msg), factor_16u, topic);
  }
  if (e == enc::TYPE_32FC1) {
    checkImage(msg, topic, 1, 4);
    return io::decodeDepth(view(msg), 1.0, topic);
  }
  throw Error("unsupported depth encoding '" + e + "' on " + topic +
              "; expected 16UC1 (millimetres) or 32FC1 (metres), see REP 118");
}

namespace {

// A NaN or infinite K or D entry would pass every comparison and poison every projection.
void checkFiniteCalibration(const sensor_msgs::CameraInfo& info, const std::string& topic) {
  const auto finite = [](const auto& values) {
    for (double v : values)
      if (!std::isfinite(v)) return false;
    return true;
  };
  if (!finite(info.K) || !finite(info.D))
    throw Error("camera_info on " + topic + " has a NaN or infinite entry in K or D; fix the camera's "
                "calibration file or set use_camera_info false to use the settings file");
  if (info.K[2] < 0 || info.K[2] > info.width || info.K[5] < 0 || info.K[5] > info.height)
    throw Error("camera_info on " + topic + ": principal point (" + std::to_string(info.K[2]) + ", " +
                std::to_string(info.K[5]) + ") lies outside the " + std::to_string(info.width) + "x" +
                std::to_string(info.height) + " image; fix the calibration");
}

}  // namespace

namespace {

// The first five plumb_bob / rational_polynomial coefficients (k1 k2 p1 p2 k3); other models and
// rectified images get none.
void setDistortion(CameraModel& cam, const cv::Mat_<double>& D, const std::string& model) {
  cam.k1 = cam.k2 = cam.p1 = cam.p2 = cam.k3 = 0;
  if (model != "plumb_bob" && model != "rational_polynomial") return;
  double* coeffs[] = {&cam.k1, &cam.k2, &cam.p1, &cam.p2, &cam.k3};
  const int n = static_cast<int>(D.total());
  for (int i = 0; i < n && i < 5; ++i) *coeffs[i] = D(i);
}

}  // namespace

Rectified parseRectified(const std::string& value) {
  if (value == "auto") return Rectified::Auto;
  if (value == "true") return Rectified::Yes;
  if (value == "false") return Rectified::No;
  throw Error("~rectified is '" + value + "'; use auto (rectified if the image topic contains "
              "image_rect), true or false");
}

bool isRectified(Rectified mode, const std::string& image_topic) {
  if (mode == Rectified::Auto) return image_topic.find("image_rect") != std::string::npos;
  return mode == Rectified::Yes;
}

CameraModel cameraFromInfo(const sensor_msgs::CameraInfo& info, const CameraModel& base,
                           const std::string& topic, bool rectified) {
  if (info.width == 0 || info.height == 0 || info.K[0] <= 0 || info.K[4] <= 0)
    throw Error("camera_info on " + topic + " has no calibration (size " +
                std::to_string(info.width) + "x" + std::to_string(info.height) + ", fx " +
                std::to_string(info.K[0]) + "); calibrate the camera or set use_camera_info "
                "false to use the settings file");
  checkFiniteCalibration(info, topic);
  if (rectified && (info.P[0] <= 0 || info.P[5] <= 0 || !std::isfinite(info.P[0] + info.P[2] + info.P[5] + info.P[6])))
    throw Error("camera_info on " + topic + " has no projection matrix P for the rectified images; "
                "fix the calibration or set ~rectified false");
  image_geometry::PinholeCameraModel model;
  try {
    model.fromCameraInfo(info);
  } catch (const std::exception& e) {
    throw Error("camera_info on " + topic + " is not a pinhole calibration: " + e.what());
  }
  CameraModel cam = base;
  // Keep bf as baseline * fx when fx changes, so ThDepth keeps its meaning in metres.
  const double baseline = base.fx > 0 ? base.bf / base.fx : 0.0;
  // Raw images: K and D. Rectified images: P (image_geometry's fx()..cy()), already undistorted.
  const cv::Matx33d& K = model.intrinsicMatrix();
  cam.fx = rectified ? model.fx() : K(0, 0);
  cam.fy = rectified ? model.fy() : K(1, 1);
  cam.cx = rectified ? model.cx() : K(0, 2);
  cam.cy = rectified ? model.cy() : K(1, 2);
  cam.bf = baseline * cam.fx;
  const cv::Size size = model.fullResolution();
  cam.width = size.width;
  cam.height = size.height;
  setDistortion(cam, rectified ? cv::Mat_<double>() : model.distortionCoeffs(), info.distortion_model);
  return cam;
}

geometry_msgs::Pose poseToMsg(const Pose& T) { return tf2::toMsg(T); }

// Quaternions from other nodes may be slightly off unit length: makePose normalises them.
Pose poseFromMsg(const geometry_msgs::Pose& m) {
  Eigen::Quaterniond q;
  Eigen::Vector3d t;
  tf2::fromMsg(m.orientation, q);
  tf2::fromMsg(m.position, t);
  return makePose(q, t);
}

geometry_msgs::Transform transformToMsg(const Pose& T) { return tf2::eigenToTransform(T).transform; }

Pose transformFromMsg(const geometry_msgs::Transform& m) {
  Eigen::Quaterniond q;
  Eigen::Vector3d t;
  tf2::fromMsg(m.rotation, q);
  tf2::fromMsg(m.translation, t);
  return makePose(q, t);
}

}  // namespace ros1
}  // namespace yolo_slam
