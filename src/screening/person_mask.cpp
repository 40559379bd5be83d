#include "yolo_slam/screening/person_mask.h"
#include "yolo_slam/screening/screener.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace yolo_slam {
namespace screening {

namespace {

constexpr uint8_t kPerson = 255;

// The depth a mask cell reads: the image pixel at its top-left corner.
float cellDepth(const cv::Mat& depth_m, int cx, int cy) {
  return depth_m.at<float>(cy * kPersonMaskStride, cx * kPersonMaskStride);
}

cv::Point cellOf(const cv::Point2f& p) {
  return {static_cast<int>(p.x) / kPersonMaskStride, static_cast<int>(p.y) / kPersonMaskStride};
}

// The cells whose top-left pixel lies in the limit rectangle, clipped to the mask.
cv::Rect cellLimit(const cv::Rect2f& limit, const cv::Size& cells) {
  const int x0 = static_cast<int>(std::ceil(std::max(0.f, limit.x) / kPersonMaskStride));
  const int y0 = static_cast<int>(std::ceil(std::max(0.f, limit.y) / kPersonMaskStride));
  const int x1 = static_cast<int>(std::ceil((limit.x + limit.width) / kPersonMaskStride));
  const int y1 = static_cast<int>(std::ceil((limit.y + limit.height) / kPersonMaskStride));
  return cv::Rect(x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)) & cv::Rect(cv::Point(0, 0), cells);
}

// Breadth-first growth of one person into the mask.
void growOne(const cv::Mat& depth_m, const PersonSeeds& person, cv::Mat& mask) {
  const cv::Rect limit = cellLimit(person.limit, mask.size());
  const auto accepts = [&](int cx, int cy) {
    if (!limit.contains(cv::Point(cx, cy)) || mask.at<uint8_t>(cy, cx) == kPerson) return false;
    const float d = cellDepth(depth_m, cx, cy);
    return d > 0.f && d >= person.lo && d <= person.hi;
  };
  std::vector<cv::Point> queue;
  for (const cv::Point2f& p : person.pts) {
    const cv::Point c = cellOf(p);
    if (!accepts(c.x, c.y)) continue;
    mask.at<uint8_t>(c.y, c.x) = kPerson;
    queue.push_back(c);
  }
  static const cv::Point kSteps[] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  for (size_t q = 0; q < queue.size(); ++q) {
    const cv::Point c = queue[q];
    const float d = cellDepth(depth_m, c.x, c.y);
    for (const cv::Point& s : kSteps) {
      const cv::Point n = c + s;
      if (!accepts(n.x, n.y) || std::abs(cellDepth(depth_m, n.x, n.y) - d) >= kPersonMaskStepPerM * d) continue;
      mask.at<uint8_t>(n.y, n.x) = kPerson;
      queue.push_back(n);
    }
  }
}

}  // namespace

cv::Mat growPersonMask(const cv::Mat& depth_m, const std::vector<PersonSeeds>& people) {
  const cv::Size cells((depth_m.cols + kPersonMaskStride - 1) / kPersonMaskStride,
                       (depth_m.rows + kPersonMaskStride - 1) / kPersonMaskStride);
  cv::Mat mask = cv::Mat::zeros(cells, CV_8U);
  for (const PersonSeeds& p : people) growOne(depth_m, p, mask);
  return mask;
}

cv::Mat personDistance(const cv::Mat& mask) {
  if (cv::countNonZero(mask) == 0)
    return cv::Mat(mask.size(), CV_32F, cv::Scalar(std::numeric_limits<float>::max()));
  cv::Mat distance;
  // distanceTransform measures to the nearest zero pixel: the person cells are the zeros.
  cv::distanceTransform(mask != kPerson, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return distance * static_cast<double>(kPersonMaskStride);
}

float distanceAt(const cv::Mat& distance, const cv::Point2f& p) {
  const cv::Point c = cellOf(p);
  if (!cv::Rect(cv::Point(0, 0), distance.size()).contains(c)) return std::numeric_limits<float>::max();
  return distance.at<float>(c.y, c.x);
}

bool personCellAt(const cv::Mat& mask, const cv::Point2f& p) {
  const cv::Point c = cellOf(p);
  return cv::Rect(cv::Point(0, 0), mask.size()).contains(c) && mask.at<uint8_t>(c.y, c.x) == kPerson;
}

int markGrownOutside(const features::FeatureFrame& frame, const cv::Mat& mask,
                     const std::vector<uint8_t>& in_any, std::vector<uint8_t>& drop) {
  int marked = 0;
  for (size_t i = 0; i < frame.keypoints.size(); ++i) {
    if (in_any[i] || drop[i] || frame.depth[i] <= 0) continue;
    if (!personCellAt(mask, frame.keypoints[i].pt)) continue;
    drop[i] = 1;
    ++marked;
  }
  return marked;
}

int markGrownInBoxes(const features::FeatureFrame& frame, const cv::Mat& mask,
                     const std::vector<BoxPerson>& boxes, const std::vector<uint8_t>& in_any,
                     std::vector<uint8_t>& drop) {
  int marked = 0;
  for (size_t i = 0; i < frame.keypoints.size(); ++i) {
    const float d = frame.depth[i];
    const cv::Point2f p = frame.keypoints[i].pt;
    if (!in_any[i] || drop[i] || d <= 0 || !personCellAt(mask, p)) continue;
    bool anothers = true;
    for (const BoxPerson& b : boxes)
      if (inside(b.region, p) && (b.keeps_all || (d >= b.lo && d <= b.hi))) anothers = false;
    if (!anothers) continue;
    drop[i] = 1;
    ++marked;
  }
  return marked;
}

int markHolesOutside(const features::FeatureFrame& frame, const cv::Mat& distance, double radius_px,
                     const std::vector<uint8_t>& in_any, std::vector<uint8_t>& drop) {
  int marked = 0;
  for (size_t i = 0; i < frame.keypoints.size(); ++i) {
    if (in_any[i] || drop[i] || frame.depth[i] > 0) continue;
    if (distanceAt(distance, frame.keypoints[i].pt) > radius_px) continue;
    drop[i] = 1;
    ++marked;
  }
  return marked;
}

}  // namespace screening
}  // namespace yolo_slam
