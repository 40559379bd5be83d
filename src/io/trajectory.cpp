#include "yolo_slam/io/trajectory.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/io/atomic_file.h"
#include "yolo_slam/io/text_table.h"

#include <cstdio>

namespace yolo_slam {
namespace io {

Trajectory readTrajectory(const std::string& path) {
  static const char* kNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  Trajectory traj;
  for (const TextRow& row : readTextTable(path)) {
    if (row.fields.size() != 8) {
      throwAtLine(path, row.line,
                  "expected 8 values 'timestamp tx ty tz qx qy qz qw', found " +
                      std::to_string(row.fields.size()));
    }
    double v[8];
    for (int k = 0; k < 8; ++k) v[k] = parseFiniteDouble(row.fields[k], path, row.line, kNames[k]);
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (q.norm() < 1e-9) throwAtLine(path, row.line, "quaternion is zero (not a rotation)");
    StampedPose p;
    p.stamp = v[0];
    p.T_wc = makePose(q, Eigen::Vector3d(v[1], v[2], v[3]));
    traj.push_back(p);
  }
  return traj;
}

const char* const kTumTrajectoryHeader = "# timestamp tx ty tz qx qy qz qw\n";

std::string formatTumPose(const StampedPose& p) {
  Eigen::Quaterniond q(p.T_wc.rotation());
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // one canonical sign
  const Eigen::Vector3d& t = p.T_wc.translation();
  char line[256];
  std::snprintf(line, sizeof line, "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", p.stamp, t.x(), t.y(), t.z(), q.x(),
                q.y(), q.z(), q.w());
  return line;
}

void writeTrajectory(const std::string& path, const Trajectory& traj) {
  std::string text = kTumTrajectoryHeader;
  for (const StampedPose& p : traj) text += formatTumPose(p);
  writeFileAtomic(path, text);
}

}  // namespace io
}  // namespace yolo_slam
