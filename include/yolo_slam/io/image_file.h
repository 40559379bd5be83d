#pragma once
// Reading image files as cv::imread does, faster for the PNG layouts RGB-D datasets use.
#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <string>

namespace yolo_slam {
namespace io {

// cv::imread(path, flags) for flags cv::IMREAD_COLOR and cv::IMREAD_UNCHANGED: the same pixels,
// an empty Mat when the file is missing, corrupt or not an image. Plain PNGs (8-bit RGB or grey,
// 16-bit grey, not interlaced, no palette or transparency chunk: what TUM, Bonn and this
// project's generator write) are inflated with libdeflate, about twice as fast as libpng with
// zlib; every other file, and any PNG the fast path doubts, goes to OpenCV.
cv::Mat readImage(const std::string& path, int flags);

// The fast path alone, on a file's bytes: true and `out` set when the bytes are a plain PNG
// whose chunks, checksums and data size are all consistent; false otherwise (out untouched).
// Always false when the library was built without libdeflate.
bool decodePlainPng(const uint8_t* data, size_t size, int flags, cv::Mat* out);

}  // namespace io
}  // namespace yolo_slam
