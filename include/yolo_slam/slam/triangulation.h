#pragma once
// New map points from a keypoint match between two keyframes, as ORB-SLAM2's
// CreateNewMapPoints makes them: triangulated when the rays' parallax beats the depth's, else
// back-projected from the better depth; kept if in front of both cameras, within the
// reprojection bounds, consistent in scale and, for RGB-D, not in space the depth camera saw
// empty (docs/ARCHITECTURE.md, "Local mapping").
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/slam/types.h"

#include <Eigen/Core>

#include <cstddef>

namespace yolo_slam {
namespace slam {

// One keyframe of a triangulation pair, with what every match of the pair needs.
struct TriangulationView {
  explicit TriangulationView(const KeyFrame& keyframe);

  const KeyFrame& kf;
  Pose T;               // T_cw
  Eigen::Vector3d O;    // camera centre
  Eigen::Matrix3d R_wc;
  double near_depth;    // kNearDepthQuantile of the static keypoints' measured depths (0: none)

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

// Share of the measured depths below which a keyframe's "near depth" is taken.
constexpr double kNearDepthQuantile = 0.05;
// Pixels around a keypoint searched for measured depths, and how many it takes to judge.
constexpr double kFreeSpaceRadius = 24.0;
constexpr std::size_t kFreeSpaceMinNeighbours = 3;

// False if keypoint i of the view has no depth and a point at depth z on its ray would lie
// nearer than free_space_ratio times the nearest depth measured around it (static keypoints
// within kFreeSpaceRadius; with fewer than kFreeSpaceMinNeighbours of them, the view's near
// depth): the depth camera saw that space empty, so the match was wrong and its rays cross
// near the camera by chance. True for keypoints with depth (the stereo reprojection bound
// holds them) and when free_space_ratio is 0.
bool outsideMeasuredFreeSpace(const TriangulationView& v, std::size_t i, double z,
                              double free_space_ratio);

// The map point of the match (keypoint i1 of v1, i2 of v2) in world coordinates, or false when
// it fails a check.
bool triangulateMatch(const CameraModel& cam, const TriangulationView& v1,
                      const TriangulationView& v2, std::size_t i1, std::size_t i2,
                      double free_space_ratio, Eigen::Vector3d& X);

}  // namespace slam
}  // namespace yolo_slam
