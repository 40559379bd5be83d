#include "yolo_slam/slam/map_point.h"

#include "yolo_slam/features/hamming.h"
#include "yolo_slam/slam/keyframe.h"

#include <algorithm>
#include <cmath>

namespace yolo_slam {
namespace slam {

MapPoint::MapPoint(long point_id, const Eigen::Vector3d& X, KeyFrame* ref, long first_frame)
    : id(point_id), Xw(X), ref_kf(ref), first_frame_id(first_frame) {
  if (ref) first_kf_id = ref->id;
}

bool MapPoint::inKeyFrame(const KeyFrame* kf) const {
  for (const auto& o : observations)
    if (o.first.get() == kf) return true;
  return false;
}

bool MapPoint::weightedObservationsAtLeast(int n) const {
  if (n <= 0) return true;
  int w = 0;
  for (const auto& o : observations)
    if ((w += o.first->f.right_u[o.second] >= 0 ? 2 : 1) >= n) return true;
  return false;
}

MapPointPtr MapPoint::resolve(MapPointPtr p) {
  // Replacement chains are short; the bound guards against a (buggy) cycle.
  for (int k = 0; p && p->bad && k < 32; ++k) p = p->replaced;
  return (p && !p->bad) ? p : nullptr;
}

void MapPoint::computeDistinctiveDescriptor() {
  std::vector<const uint8_t*> descs;
  descs.reserve(observations.size());
  for (const auto& o : observations) {
    if (o.first->bad) continue;
    descs.push_back(o.first->f.descriptors.ptr<uint8_t>(static_cast<int>(o.second)));
  }
  if (descs.empty()) return;
  const size_t n = descs.size();
  std::vector<int> dist(n * n, 0);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      dist[i * n + j] = dist[j * n + i] = features::hammingDistance(descs[i], descs[j]);
  // The descriptor with the least median distance to the others.
  int best_median = 1 << 30;
  size_t best = 0;
  std::vector<int> row(n);
  for (size_t i = 0; i < n; ++i) {
    std::copy(dist.begin() + i * n, dist.begin() + (i + 1) * n, row.begin());
    std::nth_element(row.begin(), row.begin() + (n - 1) / 2, row.end());
    int med = row[(n - 1) / 2];
    if (med < best_median) {
      best_median = med;
      best = i;
    }
  }
  descriptor = cv::Mat(1, 32, CV_8U);
  std::copy(descs[best], descs[best] + 32, descriptor.ptr<uint8_t>());
}

void MapPoint::updateNormalAndDepth() {
  if (observations.empty() || !ref_kf) return;
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  int count = 0;
  for (const auto& o : observations) {
    Eigen::Vector3d v = Xw - o.first->center();
    double norm = v.norm();
    if (norm > 0) {
      n += v / norm;
      ++count;
    }
  }
  if (count > 0 && n.norm() > 0) normal = n.normalized();
  auto it = observations.end();
  for (auto o = observations.begin(); o != observations.end(); ++o)
    if (o->first.get() == ref_kf) it = o;
  if (it == observations.end()) return;
  const double dist = (Xw - ref_kf->center()).norm();
  const auto& pyr = *ref_kf->f.pyramid;
  const int level = ref_kf->f.kps[it->second].octave;
  max_dist = dist * pyr.scale[level];
  min_dist = max_dist / pyr.scale[pyr.n_levels - 1];
}

int MapPoint::predictScale(double dist, int n_levels, double log_scale_factor) const {
  if (dist <= 0 || max_dist <= 0) return 0;
  int level = static_cast<int>(std::ceil(std::log(max_dist / dist) / log_scale_factor));
  return std::max(0, std::min(level, n_levels - 1));
}

}  // namespace slam
}  // namespace yolo_slam
