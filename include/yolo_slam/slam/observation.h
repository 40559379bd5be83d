#pragma once
// Keypoint observations handed to the optimisers: the measurement of keypoint i of a frame
// (pixel, virtual right coordinate, octave weight) as a pose-only or bundle-adjustment
// observation. Reads map objects: the caller holds Map::update_mutex.
#include "yolo_slam/optimization/bundle_adjustment.h"
#include "yolo_slam/optimization/pose_optimizer.h"
#include "yolo_slam/slam/frame.h"

namespace yolo_slam {
namespace slam {

// uv, u_right (-1 without depth: monocular residual) and inv_sigma2 of keypoint i of f.
template <class Observation>
void setMeasurement(const Frame& f, size_t i, Observation& o) {
  const cv::KeyPoint& kp = f.kps[i];
  o.uv = Eigen::Vector2d(kp.pt.x, kp.pt.y);
  o.u_right = f.right_u[i] >= 0 ? f.right_u[i] : -1.0;
  o.inv_sigma2 = f.pyramid->inv_sigma2[kp.octave];
}

// Keypoint i of f observing the (fixed) world point Xw.
inline optimization::PoseObservation poseObservation(const Frame& f, size_t i, const Eigen::Vector3d& Xw) {
  optimization::PoseObservation o;
  o.Xw = Xw;
  setMeasurement(f, i, o);
  return o;
}

// Keypoint i of keyframe kf_id (frame f) observing point point_id.
inline optimization::BaObservation baObservation(const Frame& f, size_t i, long kf_id, long point_id) {
  optimization::BaObservation o;
  o.kf_id = kf_id;
  o.point_id = point_id;
  setMeasurement(f, i, o);
  return o;
}

}  // namespace slam
}  // namespace yolo_slam
