#pragma once
// Depth image decoding: TUM 16-bit PNGs (raw / DepthMapFactor = metres) and float metres.
#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

namespace yolo_slam {
namespace io {

// The 16-bit code sensors and drivers write for a saturated or failed reading (OpenNI, many
// exporters). Read as a distance it would be 13.1 m with factor 5000: never a reading.
constexpr uint16_t kInvalidDepthCode = 65535;
constexpr double kNoDepthLimit = std::numeric_limits<double>::infinity();

// What decodeDepth made of the readings: valid ones, invalid codes (0, 65535, NaN, inf, <= 0)
// and readings farther than the range limit (all but `valid` become 0 = no depth).
struct DepthCounts {
  size_t valid = 0, invalid = 0, saturated = 0, beyond_range = 0;
};

// 16UC1 -> CV_32F metres (value / depth_map_factor; 0 and kInvalidDepthCode become 0).
// 32FC1 -> CV_32F metres (divided by depth_map_factor only if it is != 1).
// NaN, inf, values <= 0 and values beyond `max_range_m` metres become 0 (invalid). Any other
// type, an empty image, a factor <= 0 or a range <= 0 throws yolo_slam::Error naming `name`
// (usually the file). `counts`, when given, receives the tallies.
cv::Mat decodeDepth(const cv::Mat& raw, double depth_map_factor, const std::string& name,
                    double max_range_m = kNoDepthLimit, DepthCounts* counts = nullptr);

// Reads a depth image unchanged (16-bit PNG, float TIFF/EXR) and decodes it as above. Throws
// yolo_slam::Error naming the file when it is missing, a folder, corrupt, of an unsupported type,
// or when every reading is the saturated code (an export that lost the depth).
cv::Mat loadDepth(const std::string& path, double depth_map_factor);

}  // namespace io
}  // namespace yolo_slam
