#pragma once
// Finding the files of a detection model and reading its class names.
#include <opencv2/core/types.hpp>

#include <string>
#include <vector>

namespace yolo_slam {
namespace detection {

enum class ModelFormat { Darknet, Onnx };

struct ModelFiles {
  ModelFormat format = ModelFormat::Darknet;
  std::string cfg;      // Darknet only
  std::string weights;  // Darknet .weights or the .onnx file
  std::string names;
};

// `path` is a folder (with exactly one .cfg + one .weights, or exactly one .onnx, and one
// .names), a .cfg (the .weights of the same stem, else the only .weights beside it) or a .onnx.
// Throws yolo_slam::Error naming the missing or ambiguous file and how to fix it.
ModelFiles resolveModel(const std::string& path);

// One class name per non-empty line (surrounding blanks trimmed). Error if missing or empty.
std::vector<std::string> readClassNames(const std::string& path);

// [net] width/height of a Darknet cfg; Error naming file:line when absent or malformed.
cv::Size darknetInputSize(const std::string& cfg_path);

// Number of float parameters a Darknet .weights file holds for this cfg (convolutional layers
// with groups and batch norm; maxpool/route/shortcut/upsample/dropout/yolo have none). Error
// naming file:line for a layer type it does not know or a malformed value.
long long darknetParamCount(const std::string& cfg_path);

// Throws Error naming the weights file when its size is not header + 4 * darknetParamCount()
// (OpenCV reads truncated or mismatched weights silently).
void checkDarknetWeights(const std::string& cfg_path, const std::string& weights_path);

// Fixed input size (W x H) of the first non-initializer graph input of an ONNX file, read from
// its protobuf; (0,0) when the size is symbolic. Error if the file is not a readable ONNX model.
cv::Size onnxInputSize(const std::string& onnx_path);

}  // namespace detection
}  // namespace yolo_slam
