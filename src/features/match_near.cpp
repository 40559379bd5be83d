#include "yolo_slam/features/match_near.h"

#include "yolo_slam/features/hamming.h"

#include <algorithm>
#include <cmath>

namespace yolo_slam {
namespace features {

namespace {
// Running best of one query: lowest distance, then lowest index (deterministic ties whatever
// order the candidates come in).
struct Best {
  int dist, index = -1;
  explicit Best(int max_hamming) : dist(max_hamming + 1) {}
  void consider(const FeatureFrame& f, size_t i, const cv::Point2f& p, float r2, const uint8_t* desc) {
    const cv::Point2f q = f.keypoints[i].pt;
    const float ex = q.x - p.x, ey = q.y - p.y;
    if (ex * ex + ey * ey > r2) return;
    const int h = hammingDistance(desc, f.descriptors.ptr<uint8_t>(static_cast<int>(i)));
    if (h < dist || (h == dist && static_cast<int>(i) < index)) {
      dist = h;
      index = static_cast<int>(i);
    }
  }
};

bool hasDescriptors(const FeatureFrame& f) {
  return f.descriptors.rows == static_cast<int>(f.keypoints.size());
}
}  // namespace

int bestMatchNear(const FeatureFrame& frame, const cv::Point2f& p, const uint8_t* desc,
                  double radius_px, int max_hamming) {
  if (!hasDescriptors(frame)) return -1;
  Best best(max_hamming);
  const float r2 = static_cast<float>(radius_px * radius_px);
  for (size_t i = 0; i < frame.keypoints.size(); ++i) best.consider(frame, i, p, r2, desc);
  return best.index;
}

KeypointIndex::KeypointIndex(const FeatureFrame& frame, double cell_px)
    : frame_(&frame), cell_(static_cast<float>(std::max(1.0, cell_px))) {
  if (!hasDescriptors(frame) || frame.keypoints.empty()) return;
  float x1 = frame.keypoints[0].pt.x, y1 = frame.keypoints[0].pt.y;
  x0_ = x1;
  y0_ = y1;
  for (const auto& k : frame.keypoints) {
    x0_ = std::min(x0_, k.pt.x);
    y0_ = std::min(y0_, k.pt.y);
    x1 = std::max(x1, k.pt.x);
    y1 = std::max(y1, k.pt.y);
  }
  cols_ = static_cast<int>((x1 - x0_) / cell_) + 1;
  rows_ = static_cast<int>((y1 - y0_) / cell_) + 1;
  cells_.assign(static_cast<size_t>(cols_) * rows_, {});
  for (size_t i = 0; i < frame.keypoints.size(); ++i) {
    const int cx = static_cast<int>((frame.keypoints[i].pt.x - x0_) / cell_);
    const int cy = static_cast<int>((frame.keypoints[i].pt.y - y0_) / cell_);
    cells_[static_cast<size_t>(cy) * cols_ + cx].push_back(static_cast<int>(i));
  }
}

int KeypointIndex::bestMatchNear(const cv::Point2f& p, const uint8_t* desc, double radius_px,
                                 int max_hamming) const {
  if (cells_.empty()) return -1;
  Best best(max_hamming);
  const float r = static_cast<float>(radius_px), r2 = r * r;
  const int cx0 = std::max(0, static_cast<int>(std::floor((p.x - r - x0_) / cell_)));
  const int cy0 = std::max(0, static_cast<int>(std::floor((p.y - r - y0_) / cell_)));
  const int cx1 = std::min(cols_ - 1, static_cast<int>(std::floor((p.x + r - x0_) / cell_)));
  const int cy1 = std::min(rows_ - 1, static_cast<int>(std::floor((p.y + r - y0_) / cell_)));
  for (int cy = cy0; cy <= cy1; ++cy)
    for (int cx = cx0; cx <= cx1; ++cx)
      for (int i : cells_[static_cast<size_t>(cy) * cols_ + cx]) best.consider(*frame_, i, p, r2, desc);
  return best.index;
}

}  // namespace features
}  // namespace yolo_slam
