#include "yolo_slam/io/depth.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/io/image_file.h"

#include <opencv2/imgcodecs.hpp>

#include <cmath>

namespace yolo_slam {
namespace io {
namespace {

void checkArguments(const cv::Mat& raw, double depth_map_factor, double max_range_m, const std::string& name) {
  if (raw.empty()) throw Error(name + ": depth image is empty");
  if (!(depth_map_factor > 0) || !std::isfinite(depth_map_factor)) {
    throw Error(name + ": DepthMapFactor must be > 0 (5000 for TUM 16-bit PNGs, 1 for metres), got " +
                std::to_string(depth_map_factor));
  }
  if (!(max_range_m > 0))
    throw Error(name + ": DepthMaxRange must be > 0 metres, got " + std::to_string(max_range_m));
}

// One reading in metres, or 0 when it is no reading; tallied in `n`.
inline float keep(float metres, double max_range_m, DepthCounts& n) {
  if (!std::isfinite(metres) || metres <= 0.f) {
    ++n.invalid;
    return 0.f;
  }
  if (metres > max_range_m) {
    ++n.beyond_range;
    return 0.f;
  }
  ++n.valid;
  return metres;
}

}  // namespace

cv::Mat decodeDepth(const cv::Mat& raw, double depth_map_factor, const std::string& name, double max_range_m,
                    DepthCounts* counts) {
  checkArguments(raw, depth_map_factor, max_range_m, name);
  DepthCounts n;
  cv::Mat out(raw.rows, raw.cols, CV_32F);
  if (raw.type() == CV_16UC1) {
    const float inv = static_cast<float>(1.0 / depth_map_factor);
    for (int r = 0; r < raw.rows; ++r) {
      const uint16_t* s = raw.ptr<uint16_t>(r);
      float* d = out.ptr<float>(r);
      for (int c = 0; c < raw.cols; ++c) {
        if (s[c] == kInvalidDepthCode) {
          ++n.saturated;
          d[c] = 0.f;
        } else {
          d[c] = keep(s[c] * inv, max_range_m, n);
        }
      }
    }
  } else if (raw.type() == CV_32FC1) {
    const bool scale = depth_map_factor != 1.0;
    const float inv = static_cast<float>(1.0 / depth_map_factor);
    for (int r = 0; r < raw.rows; ++r) {
      const float* s = raw.ptr<float>(r);
      float* d = out.ptr<float>(r);
      for (int c = 0; c < raw.cols; ++c) d[c] = keep(scale ? s[c] * inv : s[c], max_range_m, n);
    }
  } else {
    throw Error(name + ": unsupported depth image type (" + cv::typeToString(raw.type()) +
                "); expected 16UC1 (e.g. TUM 16-bit PNG) or 32FC1 metres");
  }
  if (counts) *counts = n;
  return out;
}

cv::Mat loadDepth(const std::string& path, double depth_map_factor) {
  if (dirExists(path)) throw Error(path + ": is a folder, expected a depth image file; fix depth.txt or associations.txt");
  if (!fileExists(path)) throw Error(path + ": depth image not found");
  cv::Mat raw = readImage(path, cv::IMREAD_UNCHANGED);
  if (raw.empty()) throw Error(path + ": cannot decode depth image (corrupt or unsupported format)");
  DepthCounts n;
  cv::Mat depth = decodeDepth(raw, depth_map_factor, path, kNoDepthLimit, &n);
  if (n.valid == 0 && n.saturated > 0)
    throw Error(path + ": every reading is " + std::to_string(kInvalidDepthCode) +
                " or 0, the codes of a saturated or failed sensor reading: the image holds no depth "
                "(re-export it as 16-bit PNG, 0 = no reading, metres x DepthMapFactor)");
  return depth;
}

}  // namespace io
}  // namespace yolo_slam
