#pragma once
// Depth image decoding: TUM 16-bit PNGs (raw / DepthMapFactor = metres) and float metres.
#include <opencv2/core.hpp>

#include <string>

namespace yolo_slam {
namespace io {

// 16UC1 -> CV_32F metres (value / depth_map_factor, 0 stays 0 = invalid).
// 32FC1 -> CV_32F metres (divided by depth_map_factor only if it is != 1).
// NaN, inf and values <= 0 become 0 (invalid). Any other type, an empty image or a factor <= 0
// throws yolo_slam::Error naming `name` (usually the file).
cv::Mat decodeDepth(const cv::Mat& raw, double depth_map_factor, const std::string& name);

// Reads a depth image unchanged (16-bit PNG, float TIFF/EXR) and decodes it as above. Throws
// yolo_slam::Error naming the file when it is missing, corrupt or of an unsupported type.
cv::Mat loadDepth(const std::string& path, double depth_map_factor);

}  // namespace io
}  // namespace yolo_slam
