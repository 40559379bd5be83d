#include "yolo_slam/slam/motion_model.h"

#include "yolo_slam/optimization/se3.h"

#include <algorithm>

namespace yolo_slam {
namespace slam {

Pose fractionalStep(const Pose& V, int k) {
  if (k <= 1) return V;
  const Eigen::Matrix3d R = optimization::expSO3(optimization::logSO3(V.linear()) / k);
  // S^k has translation (I + R + ... + R^(k-1)) t: solve for t. The sum is close to k I for the
  // small turns of a frame step, far from singular.
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero(), power = Eigen::Matrix3d::Identity();
  for (int i = 0; i < k; ++i) {
    sum += power;
    power = R * power;
  }
  Pose S = Pose::Identity();
  S.linear() = R;
  S.translation() = sum.partialPivLu().solve(V.translation());
  return S;
}

void MotionHistory::push(const Pose& T_cw, size_t capacity) {
  poses_.push_back(T_cw);
  while (poses_.size() > std::max<size_t>(capacity, 2)) poses_.pop_front();
}

std::optional<Pose> MotionHistory::meanStep(int steps) const {
  if (poses_.size() < 2) return std::nullopt;
  const int k = std::max(1, std::min(steps, static_cast<int>(poses_.size()) - 1));
  const Pose V = poses_.back() * poses_[poses_.size() - 1 - static_cast<size_t>(k)].inverse();
  return fractionalStep(V, k);
}

Pose robustPrediction(const MotionHistory& history, int steps, const Pose& last_step_prediction,
                      const Pose& last_T_cw, const PredictionTolerance& tol) {
  const std::optional<Pose> step = history.meanStep(steps);
  if (!step || !step->matrix().allFinite()) return last_step_prediction;
  const Pose mean = *step * last_T_cw;
  const PoseGap gap = poseGap(mean, last_step_prediction);
  const bool outlier = gap.moved_m > kStepOutlierSigmas * tol.sigma_m ||
                       gap.turned_rad > kStepOutlierSigmas * tol.sigma_rad;
  return outlier ? mean : last_step_prediction;
}

}  // namespace slam
}  // namespace yolo_slam
