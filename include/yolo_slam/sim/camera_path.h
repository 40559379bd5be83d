#pragma once
// Continuous camera trajectories for the synthetic sequences: a replayed TUM ground truth
// (re-anchored into the room) or built-in analogues of the TUM fr3 motions.
#include "yolo_slam/common/geometry.h"

#include <string>
#include <vector>

namespace yolo_slam {
namespace sim {

// Camera pose that looks from `eye` towards `target` with world +z up (x right, y down in the
// image, z forward: the optical frame).
Pose lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
            const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

class CameraPath {
 public:
  // Built-in motions around `anchor` (T_wc at t = 0): "static" (a still tripod, sub-mm
  // tremble), "xyz" (translation along the three axes), "rpy" (rotation about the three axes at
  // one spot), "halfsphere" (on a half sphere of 0.5 m radius looking at the scene), "loop" (a
  // circle of 0.8 m radius turning a full 360 degrees, ending where it started).
  static CameraPath builtIn(const std::string& name, const Pose& anchor);
  // Replays a TUM trajectory: T_wc(t) = anchor * T_0^-1 * T(t0 + t), so the motion relative to
  // its first pose is kept and the first pose becomes `anchor`. Throws yolo_slam::Error when the
  // trajectory has fewer than 2 poses or stamps that do not increase.
  static CameraPath replay(const Trajectory& tum, const Pose& anchor, const std::string& name);
  static const std::vector<std::string>& builtInNames();

  Pose at(double t) const;          // t in seconds from the start
  double duration() const { return duration_; }  // natural length (replay: the file's span)
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  Pose anchor_ = Pose::Identity();
  double duration_ = 0;
  Trajectory samples_;  // replay: re-anchored poses, stamps from 0
};

}  // namespace sim
}  // namespace yolo_slam
