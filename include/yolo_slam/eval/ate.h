#pragma once
// Absolute trajectory error as TUM's evaluate_ate.py: associate ground-truth and estimate
// stamps (associate.py), align the estimate positions onto the ground truth with the
// closed-form rigid transform of Horn / Umeyama without scale, and report the translational
// residuals in metres.
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/eval/stats.h"

#include <utility>
#include <vector>

namespace yolo_slam {
namespace eval {

// Rigid transform T (rotation + translation, no scale) minimising sum |data_k - T model_k|^2,
// as align() in evaluate_ate.py: SVD of the cross-covariance with the reflection fix
// (det = -1 flips the smallest singular direction). Throws yolo_slam::Error if the sizes differ
// or fewer than 2 points are given.
Pose alignRigid(const std::vector<Eigen::Vector3d>& model, const std::vector<Eigen::Vector3d>& data);

// Sorted by stamp; of poses with equal stamps the last one in file order is kept (the Python
// scripts read trajectories into a dict, which does the same).
Trajectory uniqueByStamp(const Trajectory& traj);

struct AteResult {
  ErrorStats stats;                 // pairs = stats.count; rmse, mean, median, std, min, max (m)
  Pose alignment = Pose::Identity();  // T_gt_est: p_gt ~ alignment * p_est
  // Per associated pair, in ground-truth stamp order:
  std::vector<double> gt_stamps, est_stamps;
  std::vector<Eigen::Vector3d> gt_positions, est_aligned;
  std::vector<double> errors;       // |gt - aligned est| (m)
};

// Farther than this from the origin (metres) a position is not a camera trajectory but a corrupt
// file; its squares would overflow the alignment and the error statistics.
constexpr double kMaxCoordinateM = 1e9;

// gt and est are deduplicated with uniqueByStamp, associated with io::associate(gt, est,
// offset, max_diff) as evaluate_ate.py does, and aligned. Throws yolo_slam::Error if either is
// empty, fewer than 2 pairs are found ("no overlapping timestamps"), a position is beyond
// kMaxCoordinateM, or the result is not finite: never an "rmse inf".
// fixed_alignment: use this T_gt_est instead of aligning (a run in a loaded map, evaluated in
// the frame the mapping run's alignment gives that map).
AteResult computeAte(const Trajectory& gt, const Trajectory& est, double max_diff = 0.02,
                     double offset = 0.0, const Pose* fixed_alignment = nullptr);

}  // namespace eval
}  // namespace yolo_slam
