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
    // ORB-SLAM2 counts an observation with depth (stereo) twice.
    int obs = 0;
    for (const auto& o : p->observations) obs += o.first->f.right_u[o.second] >= 0 ? 2 : 1;
    if (obs >= min_obs) ++n;
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
  const int th = 15;
  std::map<KeyFramePtr, int, ById> kept;
  for (const auto& c : counter) {
    if (c.second > max_w) {
      max_w = c.second;
      best = c.first;
    }
    if (c.second >= th) {
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

std::vector<KeyFramePtr> KeyFrame::covisiblesByWeight(int w) const {
  std::vector<KeyFramePtr> out;
  for (size_t i = 0; i < ordered_connections.size() && ordered_weights[i] >= w; ++i)
    out.push_back(ordered_connections[i]);
  return out;
}

int KeyFrame::weight(const KeyFramePtr& kf) const {
  auto it = connections.find(kf);
  return it == connections.end() ? 0 : it->second;
}

double KeyFrame::sceneMedianDepth() const {
  std::vector<double> z;
  for (const auto& p : f.points) {
    if (!p || p->bad) continue;
    z.push_back((f.T_cw * p->Xw).z());
  }
  if (z.empty()) return 1.0;
  std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
  return z[z.size() / 2];
}

}  // namespace slam
}  // namespace yolo_slam
