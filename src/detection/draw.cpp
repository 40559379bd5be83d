#include "yolo_slam/detection/draw.h"

#include "yolo_slam/common/json.h"

#include <opencv2/imgproc.hpp>

#include <cstdio>

namespace yolo_slam {
namespace detection {

void drawBoxes(cv::Mat& image, const Boxes& boxes) {
  for (const auto& b : boxes) {
    const cv::Scalar colour(0, 220, 255);
    cv::Rect r(cvRound(b.rect.x), cvRound(b.rect.y), cvRound(b.rect.width), cvRound(b.rect.height));
    cv::rectangle(image, r, colour, 2);
    char text[128];
    std::snprintf(text, sizeof(text), "%s %.2f", b.label.c_str(), b.score);
    int base = 0;
    cv::Size ts = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &base);
    cv::Point org(r.x, std::max(r.y, ts.height + 4));
    cv::rectangle(image, org + cv::Point(0, -ts.height - 4), org + cv::Point(ts.width + 4, 0), colour,
                  cv::FILLED);
    cv::putText(image, text, org + cv::Point(2, -3), cv::FONT_HERSHEY_SIMPLEX, 0.5,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
}

std::string boxesJson(const Boxes& boxes) {
  std::string s = "[";
  for (size_t i = 0; i < boxes.size(); ++i) {
    const Box& b = boxes[i];
    s += (i ? "," : "") + std::string("{\"class\":\"") + jsonEscape(b.label) +
         "\",\"score\":" + jsonNumber(b.score, 4) + ",\"x1\":" + jsonNumber(b.rect.x, 6) +
         ",\"y1\":" + jsonNumber(b.rect.y, 6) + ",\"x2\":" + jsonNumber(b.rect.x + b.rect.width, 6) +
         ",\"y2\":" + jsonNumber(b.rect.y + b.rect.height, 6) + "}";
  }
  return s + "]";
}

}  // namespace detection
}  // namespace yolo_slam
