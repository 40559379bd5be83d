#include "yolo_slam/slam/map.h"

#include "yolo_slam/vocabulary/keyframe_database.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <map>
#include <thread>

namespace yolo_slam {
namespace slam {

void Map::addKeyFrame(const KeyFramePtr& kf) {
  if (keyframes_.empty() && !origin_) {
    origin_ = kf;
    kf->is_origin = true;
  }
  keyframes_.insert(kf);
  if (kfdb_ && !kf->f.bow.empty()) kfdb_->add(kf->id, kf->f.bow.bow);
}

KeyFramePtr Map::keyFrame(long id) const {
  auto it = std::lower_bound(keyframes_.begin(), keyframes_.end(), id,
                             [](const KeyFramePtr& k, long v) { return k->id < v; });
  return it != keyframes_.end() && (*it)->id == id ? *it : nullptr;
}

void Map::addMapPoint(const MapPointPtr& mp) { points_.insert(mp); }

void Map::addObservation(const MapPointPtr& mp, const KeyFramePtr& kf, size_t idx) {
  mp->observations[kf] = idx;
  kf->f.points[idx] = mp;
  if (!mp->ref_kf) mp->ref_kf = kf.get();
}

void Map::eraseObservation(const MapPointPtr& mp, const KeyFramePtr& kf) {
  auto it = mp->observations.find(kf);
  if (it == mp->observations.end()) return;
  if (it->second < kf->f.points.size() && kf->f.points[it->second] == mp)
    kf->f.points[it->second].reset();
  mp->observations.erase(it);
  if (mp->ref_kf == kf.get())
    mp->ref_kf = mp->observations.empty() ? nullptr : mp->observations.begin()->first.get();
  // ORB-SLAM2: a point seen (with depth) by one keyframe only is dropped.
  if (!mp->weightedObservationsAtLeast(3)) eraseMapPoint(mp);
}

void Map::eraseMapPoint(const MapPointPtr& mp) {
  if (!mp) return;
  mp->bad = true;
  for (const auto& o : mp->observations) {
    auto& slot = o.first->f.points[o.second];
    if (slot == mp) slot.reset();
  }
  mp->observations.clear();
  mp->ref_kf = nullptr;
  points_.erase(mp);
}

void Map::replaceMapPoint(const MapPointPtr& mp, const MapPointPtr& by) {
  if (!mp || !by || mp == by || mp->bad || by->bad) return;
  auto obs = std::move(mp->observations);
  mp->observations.clear();
  mp->bad = true;
  mp->replaced = by;
  mp->ref_kf = nullptr;
  for (const auto& o : obs) {
    const KeyFramePtr& kf = o.first;
    if (!by->inKeyFrame(kf.get())) {
      kf->f.points[o.second] = by;
      by->observations[kf] = o.second;
      if (!by->ref_kf) by->ref_kf = kf.get();
    } else if (kf->f.points[o.second] == mp) {
      kf->f.points[o.second].reset();
    }
  }
  by->found += mp->found;
  by->visible += mp->visible;
  by->dynamic = by->dynamic || mp->dynamic;
  by->computeDistinctiveDescriptor();
  points_.erase(mp);
}

void Map::eraseKeyFrame(const KeyFramePtr& kf) {
  if (!kf || kf->bad || kf->is_origin || kf->not_erase) return;
  for (const auto& c : kf->connections) c.first->eraseConnection(kf);
  for (size_t i = 0; i < kf->f.points.size(); ++i) {
    MapPointPtr mp = kf->f.points[i];
    if (mp) eraseObservation(mp, kf);
  }
  kf->connections.clear();
  kf->ordered_connections.clear();
  kf->ordered_weights.clear();

  // Re-attach the children (ORB-SLAM2 SetBadFlag): repeatedly pick the child with the strongest
  // covisibility to an already-attached candidate (initially the erased keyframe's parent).
  std::set<KeyFrame*, ById> candidates;
  if (kf->parent) candidates.insert(kf->parent.get());
  while (!kf->children.empty()) {
    int best_w = -1;
    KeyFrame* best_child = nullptr;
    KeyFramePtr best_parent;
    for (KeyFrame* child : kf->children) {
      if (child->bad) continue;
      for (size_t j = 0; j < child->ordered_connections.size(); ++j) {
        const KeyFramePtr& cand = child->ordered_connections[j];
        if (candidates.count(cand.get()) && child->ordered_weights[j] > best_w) {
          best_w = child->ordered_weights[j];
          best_child = child;
          best_parent = cand;
        }
      }
    }
    if (!best_child) break;
    best_child->parent = best_parent;
    best_parent->children.insert(best_child);
    candidates.insert(best_child);
    kf->children.erase(best_child);
  }
  // Children without covisibility to the candidates go to the erased keyframe's parent.
  for (KeyFrame* child : kf->children) {
    child->parent = kf->parent;
    if (kf->parent) kf->parent->children.insert(child);
  }
  kf->children.clear();
  if (kf->parent) {
    kf->parent->children.erase(kf.get());
    kf->T_cp = kf->Tcw() * kf->parent->Twc();
  }
  kf->loop_edges.clear();
  kf->bad = true;
  keyframes_.erase(kf);
  if (kfdb_) kfdb_->erase(kf->id);
  kf->f.releaseFeatures();
}

std::vector<KeyFramePtr> Map::keyframes() const {
  return std::vector<KeyFramePtr>(keyframes_.begin(), keyframes_.end());
}

std::vector<MapPointPtr> Map::mapPoints() const {
  return std::vector<MapPointPtr>(points_.begin(), points_.end());
}

std::unique_lock<std::mutex> Map::lockForTracking() {
  tracking_waiting_.fetch_add(1);
  std::unique_lock<std::mutex> lk(update_mutex);
  tracking_waiting_.fetch_sub(1);
  return lk;
}

void Map::yieldToTracking(std::unique_lock<std::mutex>& lk) {
  if (tracking_waiting_.load() == 0) return;
  // Unlocking alone is not a handover (the releasing thread may take the mutex straight back):
  // wait until Tracking holds it.
  constexpr auto kPoll = std::chrono::microseconds(100);
  lk.unlock();
  while (tracking_waiting_.load() > 0) std::this_thread::sleep_for(kPoll);
  lk.lock();
}

void Map::clear() {
  for (const auto& kf : keyframes_) {
    kf->f.points.clear();
    kf->connections.clear();
    kf->ordered_connections.clear();
    kf->parent.reset();
    kf->children.clear();
    kf->loop_edges.clear();
  }
  for (const auto& mp : points_) {
    mp->observations.clear();
    mp->replaced.reset();
    mp->ref_kf = nullptr;
  }
  keyframes_.clear();
  points_.clear();
  origin_.reset();
  if (kfdb_) kfdb_->clear();
}

void Map::adopt(Map& other) {
  clear();
  keyframes_.swap(other.keyframes_);
  points_.swap(other.points_);
  origin_.swap(other.origin_);
  restoreIdCounters(other.next_kf_id_.load(), other.next_point_id_.load());
  if (other.kfdb_) other.kfdb_->clear();
  if (!kfdb_) return;
  for (const auto& kf : keyframes_)
    if (!kf->f.bow.empty()) kfdb_->add(kf->id, kf->f.bow.bow);
}

namespace {
// ORB-SLAM2 DetectRelocalizationCandidates / DetectLoopCandidates: a hit is grouped with its best
// covisibles; groups scoring above this share of the best group's score survive.
constexpr size_t kGroupCovisibles = 10;
constexpr double kGroupScoreShare = 0.75;
}  // namespace

std::vector<KeyFramePtr> covisibilityGroupCandidates(const Map& map,
                                                     const std::vector<std::pair<long, double>>& hits) {
  std::map<long, double> score_of(hits.begin(), hits.end());
  std::vector<std::pair<double, KeyFramePtr>> groups;
  double best_acc = 0;
  for (const auto& h : hits) {
    KeyFramePtr kf = map.keyFrame(h.first);
    if (!kf || kf->bad) continue;
    double acc = h.second, best_score = h.second;
    KeyFramePtr best_kf = kf;
    for (const auto& nb : kf->bestCovisibles(kGroupCovisibles)) {
      auto it = score_of.find(nb->id);
      if (it == score_of.end() || nb->bad) continue;
      acc += it->second;
      if (it->second > best_score) {
        best_score = it->second;
        best_kf = nb;
      }
    }
    groups.emplace_back(acc, best_kf);
    best_acc = std::max(best_acc, acc);
  }
  std::sort(groups.begin(), groups.end(), [](const auto& a, const auto& b) {
    return a.first > b.first || (a.first == b.first && a.second->id < b.second->id);
  });
  std::vector<KeyFramePtr> cands;
  std::set<long> seen;
  for (const auto& g : groups)
    if (g.first > kGroupScoreShare * best_acc && seen.insert(g.second->id).second) cands.push_back(g.second);
  return cands;
}

}  // namespace slam
}  // namespace yolo_slam
