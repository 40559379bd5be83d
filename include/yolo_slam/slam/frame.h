#pragma once
// A tracked frame: the static keypoints of one RGB-D image with depth, a grid for projection
// search, the map-point association per keypoint and the pose estimate. Value type owned by
// Tracking (current and last frame); never shared between threads.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/features/feature_frame.h"
#include "yolo_slam/slam/types.h"

#include <opencv2/core.hpp>

#include <memory>
#include <vector>

namespace yolo_slam {
namespace vocabulary {
class Vocabulary;
}
namespace slam {

// Scale pyramid data of the ORB extractor (same formulas as features::OrbExtractor).
struct ScalePyramid {
  int n_levels = 8;
  double scale_factor = 1.2;
  double log_scale_factor = 0;
  std::vector<double> scale, inv_scale, sigma2, inv_sigma2;
  static ScalePyramid make(int n_levels, double scale_factor);
};

// Image bounds of the undistorted keypoints and the 64x48 search grid over them.
struct FrameGeometry {
  static constexpr int kGridCols = 64;
  static constexpr int kGridRows = 48;
  double min_x = 0, max_x = 640, min_y = 0, max_y = 480;
  double inv_cell_w = 0, inv_cell_h = 0;
  static FrameGeometry make(const CameraModel& cam);
  bool outside(const Eigen::Vector2d& uv) const {
    return uv.x() < min_x || uv.x() > max_x || uv.y() < min_y || uv.y() > max_y;
  }
};

class Frame {
 public:
  Frame() = default;
  // Copies the keypoints out of `ff` (undistorted coordinates) and builds the grid. `dynamic`
  // keypoints are in the grid but featuresInArea skips them unless asked (only to notice map
  // points that now lie on a dynamic object), so they never match a point.
  Frame(const features::FeatureFrame& ff, const CameraModel& cam, const FrameGeometry& geom,
        std::shared_ptr<const ScalePyramid> pyramid, long id);

  long id = -1;
  double stamp = 0;
  int N = 0;
  std::vector<cv::KeyPoint> kps;   // undistorted
  cv::Mat descriptors;             // N x 32
  std::vector<float> depth;        // metres, <= 0 invalid
  std::vector<float> right_u;      // virtual right coordinate, < 0 invalid
  std::vector<uint8_t> dynamic;    // 1: screened dynamic, never used
  std::vector<int8_t> motion;      // FeatureFrame::motion (1 static-consistent, 0 moved, -1 untested); empty: not run
  std::vector<uint8_t> boxed;      // FeatureFrame::boxed; empty: no box screening
  std::vector<MapPointPtr> points; // association per keypoint (null = none)
  std::vector<bool> outlier;       // set by pose optimisation
  BowData bow;                     // filled only when a vocabulary is used

  Pose T_cw = Pose::Identity();

  CameraModel cam;
  FrameGeometry geom;
  std::shared_ptr<const ScalePyramid> pyramid;

  void setPose(const Pose& T) { T_cw = T; }
  // The frame-to-frame evidence saw keypoint i move: found moved, or kept static inside a person
  // box without being found static-consistent.
  bool seenMoving(int i) const;
  // The frame-to-frame test saw keypoint i move (motion 0); false when it did not run.
  bool testedMoving(int i) const { return !motion.empty() && motion[i] == 0; }
  // The frame-to-frame test found keypoint i where a static point would be (motion 1).
  bool staticConsistent(int i) const { return !motion.empty() && motion[i] == 1; }
  // Frees the keypoints, descriptors, BoW and grid (N becomes 0), keeping pose and camera. For
  // erased keyframes: the trajectory still refers to them for its relative poses, and without
  // this each would keep its features (about 250 KB) for the rest of the run.
  void releaseFeatures();
  Pose Twc() const { return T_cw.inverse(); }
  Eigen::Vector3d cameraCenter() const { return T_cw.inverse().translation(); }

  // Keypoints within radius r of (x, y) on pyramid levels [min_level, max_level]
  // (max_level < 0: no upper bound). Static keypoints only, or dynamic ones only.
  std::vector<size_t> featuresInArea(double x, double y, double r, int min_level = -1,
                                     int max_level = -1, bool dynamic_only = false) const;
  // The same into `out` (cleared first): the matchers' loops reuse one buffer.
  void featuresInArea(std::vector<size_t>& out, double x, double y, double r, int min_level = -1,
                      int max_level = -1, bool dynamic_only = false) const;
  // World point of keypoint i from its depth (requires a pose and depth > 0).
  bool unprojectWorld(size_t i, Eigen::Vector3d& Xw) const;
  // Number of keypoints (static) with valid depth.
  int countWithDepth() const;
  // Static keypoints with valid depth as (depth, index), nearest first: ORB-SLAM2 turns the
  // closest ones into (temporary or keyframe) map points first.
  std::vector<std::pair<float, int>> staticByDepth() const;

 private:
  std::vector<std::vector<uint32_t>> grid_;  // kGridCols * kGridRows cells of keypoint indices
};

// Fills F's BoW slot from the descriptors of its static keypoints, unless already filled, F has
// no static keypoint or there is no vocabulary (null). The dynamic ones are left out: a frame
// full of people would otherwise look like every keyframe those people crossed, to the
// relocalisation and loop candidates, and not like the room behind them.
void computeBow(const vocabulary::Vocabulary* voc, Frame& F);

}  // namespace slam
}  // namespace yolo_slam
