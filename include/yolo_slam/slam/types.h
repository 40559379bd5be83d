#pragma once
// Forward declarations and pointer types of the SLAM map objects.
#include "yolo_slam/vocabulary/bow_vector.h"

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

namespace yolo_slam {
namespace slam {

class KeyFrame;
class MapPoint;
class Map;
using KeyFramePtr = std::shared_ptr<KeyFrame>;
using MapPointPtr = std::shared_ptr<MapPoint>;

// Bag-of-words slot (filled when a vocabulary is loaded; used by reference-keyframe tracking,
// relocalisation and loop closing): word -> weight, node -> feature indices.
struct BowData {
  vocabulary::BowVector bow;
  vocabulary::FeatureVector features;
  bool empty() const { return bow.empty(); }
};

// Vocabulary levels above the words at which FeatureVectors group features for SearchByBoW
// (ORB-SLAM2 uses 4 on its 6-level vocabulary; the shipped k=10 L=4 one needs 2 for the same
// node size: ~100 nodes).
constexpr int kBowLevelsUp = 2;

// Covisibility edges join keyframes sharing at least this many map points (ORB-SLAM2
// KeyFrame::UpdateConnections).
constexpr int kCovisibilityMinWeight = 15;

// How LocalMapping and LoopClosing run (System.sequential): each in its own thread, or inline,
// in the thread of the caller that drains their queues (System, after each tracked frame), so
// that identical input gives bit-identical results.
enum class RunMode { Threaded, Sequential };

// Orders (shared or raw) pointers by object id so that iteration order (and so every result) is
// deterministic, not dependent on heap addresses.
struct ById {
  template <class P>
  bool operator()(const P& a, const P& b) const { return a->id < b->id; }
};

// A copy of `v` read under `m` (the counters and logs behind the threads' queue mutexes).
template <class T>
T lockedCopy(std::mutex& m, const T& v) {
  std::lock_guard<std::mutex> lk(m);
  return v;
}

}  // namespace slam
}  // namespace yolo_slam
