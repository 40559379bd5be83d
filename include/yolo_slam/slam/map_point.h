#pragma once
// A 3D landmark. Owned by the Map (see map.h for the ownership and locking rules: every member
// below is read and written only with Map::update_mutex held, except `id` which is const).
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/slam/types.h"

#include <opencv2/core.hpp>

#include <map>

namespace yolo_slam {
namespace slam {

class Frame;

class MapPoint {
 public:
  MapPoint(long id, const Eigen::Vector3d& Xw, KeyFrame* ref_kf, long first_frame_id);

  const long id;                 // unique within a map; -1 for temporary visual-odometry points
  Eigen::Vector3d Xw;            // world position
  Eigen::Vector3d normal{0, 0, 1};  // mean viewing direction (unit)
  double min_dist = 0, max_dist = 0;  // scale-invariance distance range
  cv::Mat descriptor;            // 1 x 32 most distinctive descriptor of the observations
  // Observing keyframes -> keypoint index in that keyframe. Holds shared pointers: the
  // point <-> keyframe cycle is broken explicitly by Map::erase*/clear.
  std::map<KeyFramePtr, size_t, ById> observations;
  KeyFrame* ref_kf = nullptr;    // always one of `observations` (or null): raw is safe
  long first_kf_id = -1;
  long first_frame_id = -1;
  int visible = 1, found = 1;    // tracking statistics (IncreaseVisible/IncreaseFound)
  bool bad = false;
  bool dynamic = false;          // seen on a screened-dynamic keypoint in a keyframe
  MapPointPtr replaced;          // set when fused into another point
  // Tracking scratch (per frame).
  long last_seen_frame = -1, local_ref_frame = -1;

  bool inKeyFrame(const KeyFrame* kf) const;
  int numObservations() const { return static_cast<int>(observations.size()); }
  // Whether the observations, those with depth (a virtual right coordinate) counted twice
  // (ORB-SLAM2 MapPoint::nObs for stereo/RGB-D), reach n; stops counting there.
  bool weightedObservationsAtLeast(int n) const;
  double foundRatio() const { return visible > 0 ? static_cast<double>(found) / visible : 0.0; }
  // Follows the replacement chain; returns the live point (or null if it ended in a bad one).
  static MapPointPtr resolve(MapPointPtr p);

  void computeDistinctiveDescriptor();
  void updateNormalAndDepth();
  // ORB-SLAM2 PredictScale: expected pyramid level when seen at `dist`.
  int predictScale(double dist, int n_levels, double log_scale_factor) const;
};

}  // namespace slam
}  // namespace yolo_slam
