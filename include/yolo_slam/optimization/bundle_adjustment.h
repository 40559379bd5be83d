#pragma once
// Bundle adjustment of keyframe poses (T_cw) and map points with Ceres (ORB-SLAM2's
// LocalBundleAdjustment / GlobalBundleAdjustemnt without g2o).
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/geometry.h"

#include <Eigen/Core>

#include <atomic>
#include <vector>

namespace yolo_slam {
namespace optimization {

struct BaKeyFrame {
  long id;
  Pose T_cw;
  bool fixed;  // held constant (ORB-SLAM2's fixed outer keyframes / the origin keyframe)
};
struct BaPoint {
  long id;
  Eigen::Vector3d Xw;
};
struct BaObservation {
  long kf_id;
  long point_id;
  Eigen::Vector2d uv;      // undistorted keypoint
  double u_right = -1;     // < 0: monocular residual; else RGB-D 3-row residual
  double inv_sigma2 = 1;   // 1 / sigma^2 of the keypoint's octave
};
struct BaProblem {
  std::vector<BaKeyFrame> keyframes;
  std::vector<BaPoint> points;
  std::vector<BaObservation> observations;
};
struct BaResult {
  // Per observation, at the final estimate: chi2 > 5.991 (mono) / 7.815 (RGB-D), the point at
  // or behind the camera, or an unusable observation (non-finite values, inv_sigma2 <= 0).
  // The caller erases these observations from the map (ORB-SLAM2 does so after local BA).
  std::vector<bool> outlier_observation;
  int iterations = 0;         // Ceres iterations over all stages
  // Robust (Huber) cost 0.5 * sum rho(chi2) over all usable observations, before and after;
  // comparable with each other (unlike the per-stage Ceres costs).
  double initial_cost = 0, final_cost = 0;
  bool stopped = false;       // the stop flag cut the optimisation short
};

// ORB-SLAM2 LocalBundleAdjustment: Huber (delta sqrt(5.991) / sqrt(7.815)); 5 iterations;
// observations with chi2 above the threshold or negative depth are dropped; 10 more iterations
// without the robust kernel. Non-fixed poses and all observed points are updated in place
// (points without observations, points whose observations all end as outliers, and fixed
// keyframes are untouched; non-finite results are not written). The stop flag is polled after every iteration (a new keyframe arrived): the
// current estimate is kept and the second stage skipped. Throws yolo_slam::Error when an
// observation names a keyframe or point id that is not in the problem, or ids are duplicated.
// Prefer the std::atomic overload; the bool* one reads the flag with an atomic load, which is
// only race-free if the writer also writes it atomically.
BaResult localBundleAdjustment(const CameraModel& cam, BaProblem& problem,
                               const bool* stop_flag = nullptr);
BaResult localBundleAdjustment(const CameraModel& cam, BaProblem& problem,
                               const std::atomic<bool>& stop_flag);

// ORB-SLAM2 GlobalBundleAdjustemnt: one stage of `iterations` iterations with Huber; nothing is
// dropped during the run, outliers are only reported. Same update/Error rules as above.
BaResult globalBundleAdjustment(const CameraModel& cam, BaProblem& problem, int iterations = 10);
BaResult globalBundleAdjustment(const CameraModel& cam, BaProblem& problem, int iterations,
                                const std::atomic<bool>& stop_flag);

}  // namespace optimization
}  // namespace yolo_slam
