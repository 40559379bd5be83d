#include "yolo_slam/slam/keyframe.h"

#include "yolo_slam/slam/map_point.h"

#include <algorithm>

namespace yolo_slam {
namespace slam {

KeyFrame::KeyFrame(long kf_id, const Frame& frame) : id(kf_id), frame_id(frame.id), f(frame) {
  f.outlier.assign(f.N, false);
}

std::vector<MapPointPtr> KeyFrame::mapPoints() const {
  std::vector<MapPointPtr> out;
  for (const auto& p : f.points)
    if (p && !p->bad) out.push_back(p);
  return out;
}

int KeyFrame::trackedMapPoints(int min_obs) const {
  int n = 0;
  for (const auto& p : f.points) {
    if (!p || p->bad) continue;
    if (min_obs <= 0) {
      ++n;
      continue;
    }
    if (p->weightedObservationsAtLeast(min_obs)) ++n;
  }
  return n;
}

void KeyFrame::addConnection(const KeyFramePtr& kf, int w) {
  auto it = connections.find(kf);
  if (it != connections.end() && it->second == w) return;
  connections[kf] = w;
  updateBestCovisibles();
}

void KeyFrame::eraseConnection(const KeyFramePtr& kf) {
  if (connections.erase(kf)) updateBestCovisibles();
}

void KeyFrame::updateBestCovisibles() {
  std::vector<std::pair<int, KeyFramePtr>> v;
  v.reserve(connections.size());
  for (const auto& c : connections) v.emplace_back(c.second, c.first);
  // Decreasing weight; ties by id for determinism.
  std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) {
    if (a.first != b.first) return a.first > b.first;
    return a.second->id < b.second->id;
  });
  ordered_connections.clear();
  ordered_weights.clear();
  for (auto& e : v) {
    ordered_weights.push_back(e.first);
    ordered_connections.push_back(e.second);
  }
}

void KeyFrame::updateConnections() {
  std::map<KeyFramePtr, int, ById> counter;
  for (const auto& p : f.points) {
    if (!p || p->bad) continue;
    for (const auto& o : p->observations) {
      if (o.first.get() == this || o.first->bad) continue;
      counter[o.first]++;
    }
  }
  if (counter.empty()) return;
  int max_w = 0;
  KeyFramePtr best;
  std::map<KeyFramePtr, int, ById> kept;
  for (const auto& c : counter) {
    if (c.second > max_w) {
      max_w = c.second;
      best = c.first;
    }
    if (c.second >= kCovisibilityMinWeight) {
      kept[c.first] = c.second;
      c.first->addConnection(self(), c.second);
    }
  }
  if (kept.empty()) {
    kept[best] = max_w;
    best->addConnection(self(), max_w);
  }
  connections = std::move(kept);
  updateBestCovisibles();
  if (first_connection && !is_origin && !ordered_connections.empty()) {
    parent = ordered_connections.front();
    parent->children.insert(this);
    first_connection = false;
  }
}

std::vector<KeyFramePtr> KeyFrame::bestCovisibles(size_t n) const {
  if (ordered_connections.size() <= n) return ordered_connections;
  return std::vector<KeyFramePtr>(ordered_connections.begin(), ordered_connections.begin() + n);
}

int KeyFrame::weight(const KeyFramePtr& kf) const {
  auto it = connections.find(kf);
  return it == connections.end() ? 0 : it->second;
}

KeyFramePtr liveAncestor(KeyFramePtr kf, Pose* T_kr) {
  Pose T = Pose::Identity();
  while (kf && kf->bad) {
    T = T * kf->T_cp;
    kf = kf->parent;
  }
  if (T_kr) *T_kr = T;
  return kf;
}

}  // namespace slam
}  // namespace yolo_slam
