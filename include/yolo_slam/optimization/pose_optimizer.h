#pragma once
// Pose-only optimisation of one frame against fixed 3D points (ORB-SLAM2 PoseOptimization).
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/geometry.h"

#include <Eigen/Core>

#include <vector>

namespace yolo_slam {
namespace optimization {

struct PoseObservation {
  Eigen::Vector3d Xw;          // map point, world frame (held fixed)
  Eigen::Vector2d uv;          // undistorted keypoint, pixels
  double u_right = -1;         // keypoint's u - bf/depth; < 0: monocular (2-row) residual
  double inv_sigma2 = 1;       // 1 / sigma^2 of the keypoint's octave (OrbExtractor::invLevelSigma2)
};

// ORB-SLAM2's PoseOptimization rounds.
constexpr int kPoseRounds = 4;

// A Gaussian prior on the pose: where a motion model predicts the camera (T_cw), with standard
// deviations for the camera centre (metres) and the rotation (radians). Its residual is the
// rotation vector of R R_p^T over sigma_rad and R (c_p - c) over sigma_m (c: camera centre).
struct PosePrior {
  Pose T_cw = Pose::Identity();
  double sigma_m = 0.02;
  double sigma_rad = 0.0175;
};

// Refines T_cw (world -> camera) in place, starting from the given value. ORB-SLAM2 semantics:
// Huber loss (delta sqrt(5.991) mono, sqrt(7.815) RGB-D), `rounds` rounds of up to 10
// Levenberg-Marquardt iterations; after each round every observation (also the current
// outliers) is re-classified: chi2 > 5.991 / 7.815 or a point at or behind the camera is an
// outlier and does not take part in the next round; the robust kernel is dropped for the last
// round; stops early when fewer than 10 inliers remain. Unlike ORB-SLAM2 each round continues
// from the previous round's pose instead of the initial one.
//
// is_outlier is output only (resized to obs.size()); observations with non-finite values or
// inv_sigma2 <= 0 are outliers. Returns the number of inliers; with fewer than 3 usable
// observations returns 0 and leaves T_cw unchanged (is_outlier then flags only unusable ones).
// A result that is not finite also leaves T_cw unchanged and returns 0. With a prior (not null)
// its residual takes part in every round (beyond ORB-SLAM2).
int optimizePose(const CameraModel& cam, Pose& T_cw, const std::vector<PoseObservation>& obs,
                 std::vector<bool>& is_outlier, int rounds = kPoseRounds, const PosePrior* prior = nullptr);

}  // namespace optimization
}  // namespace yolo_slam
