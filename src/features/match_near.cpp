#include "yolo_slam/features/match_near.h"

#include "yolo_slam/features/hamming.h"

namespace yolo_slam {
namespace features {

int bestMatchNear(const FeatureFrame& frame, const cv::Point2f& p, const uint8_t* desc,
                  double radius_px, int max_hamming) {
  if (frame.descriptors.rows != static_cast<int>(frame.keypoints.size())) return -1;
  const float r2 = static_cast<float>(radius_px * radius_px);
  int best = max_hamming + 1, best_i = -1;
  for (size_t i = 0; i < frame.keypoints.size(); ++i) {
    const cv::Point2f q = frame.keypoints[i].pt;
    const float ex = q.x - p.x, ey = q.y - p.y;
    if (ex * ex + ey * ey > r2) continue;
    const int h = hammingDistance(desc, frame.descriptors.ptr<uint8_t>(static_cast<int>(i)));
    if (h < best) {  // strict: the lowest index wins ties
      best = h;
      best_i = static_cast<int>(i);
    }
  }
  return best_i;
}

}  // namespace features
}  // namespace yolo_slam
