#pragma once
// The map: the single owner of KeyFrames and MapPoints.
//
// OWNERSHIP. Keyframes and points are created by Tracking/LocalMapping and handed to the Map
// (addKeyFrame/addMapPoint); only the Map erases them (eraseKeyFrame/eraseMapPoint/replace).
// Objects are held by std::shared_ptr: the Map's sets, the keyframe <-> point association
// (KeyFrame::f.points, MapPoint::observations), covisibility edges and the spanning-tree parent
// link. Erasing flags the object `bad`, removes it from the Map and breaks every link to and from
// it, so it is freed as soon as the last outside holder (e.g. Tracking's last frame, a
// trajectory record that still refers to an erased reference keyframe) lets go. Holders must
// check `bad` and follow MapPoint::replaced. clear() breaks all cycles before dropping the sets.
// Nobody keeps a raw pointer beyond the scope of a locked section, except the ones documented in
// keyframe.h / map_point.h (children, ref_kf) which the erase logic keeps valid.
//
// LOCKING. One coarse mutex, `update_mutex`, guards the whole map graph: the Map's sets and every
// mutable member of every KeyFrame and MapPoint (poses, positions, associations, covisibility,
// tree, flags, counters). Tracking holds it for the whole processing of a frame; LocalMapping
// holds it for each step of a keyframe, hands it to a waiting Tracking between the parts of a
// long step (yieldToTracking), and releases it while Ceres solves the local bundle
// adjustment on a copy (BaProblem) and re-takes it to write the result back; System takes it for
// snapshots/trajectories. LoopClosing holds it for loop detection + verification, for the whole
// correction (pose propagation, fusion, essential graph) and for the global-BA copy/write-back,
// never while it waits for LocalMapping to pause (see loop_closing.h). There are no per-object
// mutexes, so there is no lock-order problem inside the map; the only other mutexes
// (LocalMapping/LoopClosing queues, System stats, the KeyFrameDatabase's) are always taken
// AFTER update_mutex or alone, never the other way round.
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/slam/types.h"

#include <atomic>
#include <mutex>
#include <set>
#include <vector>

namespace yolo_slam {
namespace vocabulary {
class KeyFrameDatabase;
}
namespace slam {

class Map {
 public:
  Map() = default;
  ~Map() { clear(); }
  Map(const Map&) = delete;
  Map& operator=(const Map&) = delete;

  // Guards everything described above. Lock order: update_mutex first.
  mutable std::mutex update_mutex;

  // update_mutex for Tracking: the caller counts as waiting until it holds the lock, so that
  // a holder in a long step can let it go first (a frame should not wait for a whole step).
  std::unique_lock<std::mutex> lockForTracking();
  // Called with update_mutex held (lk), between parts of a step that need not be atomic
  // together: when Tracking waits, releases the lock until Tracking has taken it, then takes it
  // back (after Tracking's frame). The caller must re-check `bad` on what it holds afterwards.
  void yieldToTracking(std::unique_lock<std::mutex>& lk);

  // Ids are unique over the map's lifetime (not reused after clear()); atomic so they can be
  // drawn without the mutex.
  long newKeyFrameId() { return next_kf_id_++; }
  long newPointId() { return next_point_id_++; }
  // The ids the next keyframe / point will get (saved in map files so that ids stay unique).
  long nextKeyFrameId() const { return next_kf_id_.load(); }
  long nextPointId() const { return next_point_id_.load(); }
  // Map files: ids continue after those of the loaded map. Caller holds update_mutex.
  void restoreIdCounters(long next_kf_id, long next_point_id) {
    next_kf_id_ = next_kf_id;
    next_point_id_ = next_point_id;
  }

  // Place-recognition index kept in step with the keyframe set: addKeyFrame adds a keyframe with
  // a filled BoW slot, eraseKeyFrame and clear remove. Set once before use (System); may be null.
  // The database has its own mutex, always taken after update_mutex (never the other way).
  void setKeyFrameDatabase(vocabulary::KeyFrameDatabase* db) { kfdb_ = db; }
  vocabulary::KeyFrameDatabase* keyFrameDatabase() const { return kfdb_; }

  // --- all below: caller holds update_mutex ---
  void addKeyFrame(const KeyFramePtr& kf);
  KeyFramePtr keyFrame(long id) const;          // null if not (or no longer) in the map
  void addMapPoint(const MapPointPtr& mp);
  // Adds the observation both ways (kf->f.points[idx] = mp and mp->observations[kf] = idx).
  static void addObservation(const MapPointPtr& mp, const KeyFramePtr& kf, size_t idx);
  // Removes one observation both ways; a point left with <= 2 observations is erased
  // (ORB-SLAM2 EraseObservation).
  void eraseObservation(const MapPointPtr& mp, const KeyFramePtr& kf);
  void eraseMapPoint(const MapPointPtr& mp);
  // Erases a keyframe: observations, covisibility edges, spanning-tree re-parenting of its
  // children (ORB-SLAM2 SetBadFlag). The first keyframe is never erased.
  void eraseKeyFrame(const KeyFramePtr& kf);
  // `mp` is fused into `by`: its observations move to `by` (ORB-SLAM2 MapPoint::Replace).
  void replaceMapPoint(const MapPointPtr& mp, const MapPointPtr& by);

  std::vector<KeyFramePtr> keyframes() const;   // sorted by id
  std::vector<MapPointPtr> mapPoints() const;   // sorted by id
  size_t numKeyFrames() const { return keyframes_.size(); }
  size_t numMapPoints() const { return points_.size(); }
  KeyFramePtr origin() const { return origin_; }

  // Drops everything, breaking the reference cycles first.
  void clear();
  // Replaces this map's contents by `other`'s (a map loaded from a file): clears this map, takes
  // other's keyframes, points, origin and id counters, and indexes the keyframes in this map's
  // keyframe database. `other` is left empty. Caller holds update_mutex; `other` is not shared.
  void adopt(Map& other);

 private:
  std::atomic<int> tracking_waiting_{0};  // callers of lockForTracking not yet holding the lock
  std::set<KeyFramePtr, ById> keyframes_;
  std::set<MapPointPtr, ById> points_;
  KeyFramePtr origin_;
  vocabulary::KeyFrameDatabase* kfdb_ = nullptr;
  std::atomic<long> next_kf_id_{0};
  std::atomic<long> next_point_id_{0};
};

// ORB-SLAM2's candidate grouping for loop detection and relocalisation: each bag-of-words hit
// (keyframe id, score) is grouped with those of its 10 best covisible keyframes that are hits
// too; a group scores the sum of its hits and is represented by its best-scoring keyframe.
// Returns the representatives of the groups scoring more than 0.75 x the best group, best
// group first (ties by keyframe id), each keyframe once. Caller holds map.update_mutex.
std::vector<KeyFramePtr> covisibilityGroupCandidates(const Map& map,
                                                     const std::vector<std::pair<long, double>>& hits);

}  // namespace slam
}  // namespace yolo_slam
