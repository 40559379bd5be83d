#pragma once
// Output helpers for tools: drawing boxes and JSON.
#include "yolo_slam/common/json.h"
#include "yolo_slam/detection/box.h"

#include <opencv2/core.hpp>

#include <string>

namespace yolo_slam {
namespace detection {

// Draws each box with its label and score onto `image` (BGR, modified in place).
void drawBoxes(cv::Mat& image, const Boxes& boxes);

// [{"class":"person","score":0.9,"x1":..,"y1":..,"x2":..,"y2":..}, ...]
Json boxesJson(const Boxes& boxes);

}  // namespace detection
}  // namespace yolo_slam
