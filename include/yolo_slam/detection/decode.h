#pragma once
// Turning raw network outputs into boxes: mapping from network input to image pixels, decoding
// of YOLO rows and NanoDet heads, per-class non-maximum suppression.
#include "yolo_slam/detection/box.h"

#include <opencv2/core.hpp>

#include <vector>

namespace yolo_slam {
namespace detection {

// How an image was fitted into the network input: net = img * scale + pad.
struct InputTransform {
  double scale_x = 1, scale_y = 1, pad_x = 0, pad_y = 0;
  // Plain resize (stretch) or letterbox (uniform scale, centred, padded).
  static InputTransform make(cv::Size image, cv::Size input, bool letterbox);
  cv::Rect2f toImage(const cv::Rect2f& net_rect) const;
};

// The image as the network sees it: resized or letterboxed (grey 114 padding), 8-bit BGR.
cv::Mat fitToInput(const cv::Mat& bgr, cv::Size input, const InputTransform& t);

// A candidate before NMS, in network-input pixels.
struct Candidate {
  int class_id;
  float score;
  cv::Rect2f rect;
};

// YOLO rows [cx, cy, w, h, objectness, class scores...] (one row per anchor and cell).
// normalized: coordinates are in [0,1] of the input (OpenCV Darknet region layers) rather
// than input pixels. class_scores_include_objectness: OpenCV's region layer already
// multiplies class scores by objectness; YOLOv5-style ONNX exports do not.
// Only classes with keep[class] are returned, with score >= conf.
void decodeYoloRows(const cv::Mat& rows, cv::Size input, bool normalized,
                    bool class_scores_include_objectness, const std::vector<bool>& keep,
                    float conf, std::vector<Candidate>& out);

// One NanoDet level: cls (cells x C, sigmoid scores) and reg (cells x 4*(R+1), distribution
// logits of the left/top/right/bottom distances in units of `stride`), cells row-major over a
// ceil(H/stride) x ceil(W/stride) grid.
void decodeNanoDetLevel(const cv::Mat& cls, const cv::Mat& reg, int stride, cv::Size input,
                        const std::vector<bool>& keep, float conf, std::vector<Candidate>& out);

// Per-class NMS (cv::dnn::NMSBoxes), mapping to the image and clipping to it; sorted by score.
Boxes suppressAndMap(const std::vector<Candidate>& cands, float conf, float nms,
                     const InputTransform& t, cv::Size image,
                     const std::vector<std::string>& class_names);

float iou(const cv::Rect2f& a, const cv::Rect2f& b);

}  // namespace detection
}  // namespace yolo_slam
