#pragma once
// Constant-velocity prediction from the poses of the last tracked frames.
//
// ORB-SLAM2 predicts a frame from the last step alone (velocity = T_cw(t-1) T_cw(t-2)^-1). One
// frame whose pose a person dragged off then sets the velocity of the next, and where the static
// scene leaves a direction free (a far wall cannot see the camera move along its axis) the
// prediction carries the drag on frame after frame. The mean step over a few frames lets one bad
// step move the prediction by a fraction of itself.
#include "yolo_slam/common/geometry.h"

#include <deque>
#include <optional>

namespace yolo_slam {
namespace slam {

// The step S with S^k = V (k >= 1): the rotation's angle divided by k about the same axis, and
// the translation that, applied k times with that rotation, adds up to V's.
Pose fractionalStep(const Pose& V, int k);

// How far a prediction may move per frame before it is an outlier: the motion prior's sigmas.
struct PredictionTolerance {
  double sigma_m = 0;
  double sigma_rad = 0;
};

// Within this many sigmas of the mean step's prediction, the last step's stands.
constexpr double kStepOutlierSigmas = 3.0;

// Poses T_cw of consecutive tracked frames, newest last.
class MotionHistory {
 public:
  void clear() { poses_.clear(); }
  // Keeps the newest `capacity` poses (at least 2).
  void push(const Pose& T_cw, size_t capacity);
  size_t size() const { return poses_.size(); }
  // The mean of the last `steps` frame steps (fewer when fewer poses are held), as a velocity
  // T_cw(t) T_cw(t-1)^-1; none with fewer than two poses.
  std::optional<Pose> meanStep(int steps) const;

 private:
  std::deque<Pose, Eigen::aligned_allocator<Pose>> poses_;
};

// The prediction one step past `last_T_cw`: `last_step_prediction` (the last step applied, as
// ORB-SLAM2) unless it lies more than kStepOutlierSigmas sigmas from the prediction of the mean
// of the last `steps` steps of `history`, which then replaces it. A camera's step changes by
// millimetres from one frame to the next, a person's pull by centimetres.
Pose robustPrediction(const MotionHistory& history, int steps, const Pose& last_step_prediction,
                      const Pose& last_T_cw, const PredictionTolerance& tol);

}  // namespace slam
}  // namespace yolo_slam
