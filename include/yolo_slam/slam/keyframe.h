#pragma once
// A keyframe: a frozen Frame with its pose, map-point associations, covisibility graph edges,
// spanning-tree links, loop edges and BoW slot. Owned by the Map (see map.h: every mutable
// member is accessed only with Map::update_mutex held; `id` and `frame_id` are const).
#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/types.h"

#include <map>
#include <set>
#include <vector>

namespace yolo_slam {
namespace slam {

class KeyFrame : public std::enable_shared_from_this<KeyFrame> {
 public:
  KeyFrame(long id, const Frame& frame);

  const long id;
  const long frame_id;
  Frame f;                      // keypoints, grid, pose (f.T_cw), map points (f.points), BoW

  // Covisibility graph: keyframes sharing >= kCovisibilityMinWeight points (or the best one),
  // weight = shared points.
  std::map<KeyFramePtr, int, ById> connections;
  std::vector<KeyFramePtr> ordered_connections;   // by decreasing weight
  std::vector<int> ordered_weights;
  // Spanning tree. A child does not own its parent's lifetime link in reverse: children are raw
  // pointers, valid because an erased keyframe removes itself from its parent's children.
  KeyFramePtr parent;
  std::set<KeyFrame*, ById> children;   // by id: deterministic iteration
  bool first_connection = true;
  std::set<KeyFramePtr, ById> loop_edges;          // closed loops (essential-graph edges)
  bool bad = false;
  bool not_erase = false;                          // protected from culling (loop closing)
  bool is_origin = false;                          // first keyframe of the map: never erased
  Pose T_cp = Pose::Identity();                    // pose relative to parent, kept when erased
  // Tracking scratch (per frame, as MapPoint::local_ref_frame): the frame whose local map last
  // took this keyframe in, and how many of that frame's points it observes.
  long local_ref_frame = -1;
  int local_count = 0;

  const Pose& Tcw() const { return f.T_cw; }
  Pose Twc() const { return f.T_cw.inverse(); }
  Eigen::Vector3d center() const { return f.T_cw.inverse().translation(); }

  std::vector<MapPointPtr> mapPoints() const;      // live, non-null
  // Points with >= min_obs observations, counted as MapPoint::weightedObservationsAtLeast.
  int trackedMapPoints(int min_obs) const;

  // Rebuilds this keyframe's covisibility edges from its points (both directions) and, on the
  // first call, attaches it to the spanning tree under the best-covisible keyframe.
  void updateConnections();
  void addConnection(const KeyFramePtr& kf, int weight);
  void eraseConnection(const KeyFramePtr& kf);
  void updateBestCovisibles();
  std::vector<KeyFramePtr> bestCovisibles(size_t n) const;
  int weight(const KeyFramePtr& kf) const;

  KeyFramePtr self() { return shared_from_this(); }
};

// The first live keyframe up the spanning tree from kf: kf itself unless erased (null if the
// chain ends). T_kr (may be null) receives kf's pose relative to it: erased keyframes keep
// their pose relative to the parent (T_cp). Caller holds Map::update_mutex.
KeyFramePtr liveAncestor(KeyFramePtr kf, Pose* T_kr = nullptr);

}  // namespace slam
}  // namespace yolo_slam
