#include "yolo_slam/io/depth.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"

#include <opencv2/imgcodecs.hpp>

#include <cmath>

namespace yolo_slam {
namespace io {

cv::Mat decodeDepth(const cv::Mat& raw, double depth_map_factor, const std::string& name) {
  if (raw.empty()) throw Error(name + ": depth image is empty");
  if (!(depth_map_factor > 0) || !std::isfinite(depth_map_factor)) {
    throw Error(name + ": DepthMapFactor must be > 0 (5000 for TUM 16-bit PNGs, 1 for metres), got " +
                std::to_string(depth_map_factor));
  }
  cv::Mat out(raw.rows, raw.cols, CV_32F);
  if (raw.type() == CV_16UC1) {
    const float inv = static_cast<float>(1.0 / depth_map_factor);
    for (int r = 0; r < raw.rows; ++r) {
      const uint16_t* s = raw.ptr<uint16_t>(r);
      float* d = out.ptr<float>(r);
      for (int c = 0; c < raw.cols; ++c) d[c] = s[c] * inv;
    }
  } else if (raw.type() == CV_32FC1) {
    const bool scale = depth_map_factor != 1.0;
    const float inv = static_cast<float>(1.0 / depth_map_factor);
    for (int r = 0; r < raw.rows; ++r) {
      const float* s = raw.ptr<float>(r);
      float* d = out.ptr<float>(r);
      for (int c = 0; c < raw.cols; ++c) {
        float v = scale ? s[c] * inv : s[c];
        d[c] = (std::isfinite(v) && v > 0.f) ? v : 0.f;
      }
    }
  } else {
    throw Error(name + ": unsupported depth image type (" + cv::typeToString(raw.type()) +
                "); expected 16UC1 (e.g. TUM 16-bit PNG) or 32FC1 metres");
  }
  return out;
}

cv::Mat loadDepth(const std::string& path, double depth_map_factor) {
  if (!fileExists(path)) throw Error(path + ": depth image not found");
  cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (raw.empty()) throw Error(path + ": cannot decode depth image (corrupt or unsupported format)");
  return decodeDepth(raw, depth_map_factor, path);
}

}  // namespace io
}  // namespace yolo_slam
