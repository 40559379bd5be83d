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

Json boxesJson(const Boxes& boxes) {
  Json out = Json::array();
  for (const Box& b : boxes)
    out.push_back({{"class", b.label}, {"score", jsonNumber(b.score)}, {"x1", jsonNumber(b.rect.x)},
                   {"y1", jsonNumber(b.rect.y)}, {"x2", jsonNumber(b.rect.x + b.rect.width)},
                   {"y2", jsonNumber(b.rect.y + b.rect.height)}});
  return out;
}

}  // namespace detection
}  // namespace yolo_slam
