#include "yolo_slam/io/trajectory.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/io/text_table.h"

#include <cstdio>
#include <memory>

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

void writeTrajectory(const std::string& path, const Trajectory& traj) {
  const std::string tmp = path + ".tmp";
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(tmp.c_str(), "w"), &std::fclose);
  if (!f) throw Error(path + ": cannot write trajectory (does the folder exist and is it writable?)");
  bool ok = std::fprintf(f.get(), "# timestamp tx ty tz qx qy qz qw\n") > 0;
  for (const StampedPose& p : traj) {
    Eigen::Quaterniond q(p.T_wc.rotation());
    q.normalize();
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // one canonical sign
    const Eigen::Vector3d& t = p.T_wc.translation();
    ok = ok && std::fprintf(f.get(), "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", p.stamp, t.x(),
                            t.y(), t.z(), q.x(), q.y(), q.z(), q.w()) > 0;
  }
  ok = (std::fflush(f.get()) == 0) && ok;
  ok = (std::fclose(f.release()) == 0) && ok;
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw Error(path + ": failed to write trajectory (disk full or not writable?)");
  }
}

}  // namespace io
}  // namespace yolo_slam
