#include "yolo_slam/sim/camera_path.h"

#include "yolo_slam/common/error.h"

#include <algorithm>
#include <cmath>

namespace yolo_slam {
namespace sim {

namespace {
constexpr double kPi = 3.14159265358979323846;
double deg(double d) { return d * kPi / 180.0; }
Eigen::Matrix3d rotXYZ(double rx, double ry, double rz) {
  return (Eigen::AngleAxisd(rz, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(ry, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rx, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}
}  // namespace

Pose lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = z.cross(up).normalized();  // image right
  Eigen::Vector3d y = z.cross(x);                // image down
  Pose T = Pose::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

const std::vector<std::string>& CameraPath::builtInNames() {
  static const std::vector<std::string> n = {"static", "xyz", "rpy", "halfsphere", "loop"};
  return n;
}

CameraPath CameraPath::builtIn(const std::string& name, const Pose& anchor) {
  const auto& n = builtInNames();
  if (std::find(n.begin(), n.end(), name) == n.end())
    throw Error("unknown camera motion '" + name +
                "': use static, xyz, rpy, halfsphere, loop or a TUM groundtruth file");
  CameraPath p;
  p.name_ = name;
  p.anchor_ = anchor;
  p.duration_ = name == "loop" ? 40.0 : name == "halfsphere" ? 35.0 : 30.0;
  return p;
}

CameraPath CameraPath::replay(const Trajectory& tum, const Pose& anchor, const std::string& name) {
  if (tum.size() < 2) throw Error("trajectory " + name + " has fewer than 2 poses: nothing to replay");
  CameraPath p;
  p.name_ = name;
  p.anchor_ = anchor;
  const Pose A = anchor * tum.front().T_wc.inverse();
  for (size_t i = 0; i < tum.size(); ++i) {
    if (i > 0 && !(tum[i].stamp > tum[i - 1].stamp))
      throw Error("trajectory " + name + ": stamps do not increase at pose " + std::to_string(i + 1) +
                  " (sort the file by time)");
    StampedPose s;
    s.stamp = tum[i].stamp - tum.front().stamp;
    s.T_wc = A * tum[i].T_wc;
    p.samples_.push_back(s);
  }
  p.duration_ = p.samples_.back().stamp;
  return p;
}

Pose CameraPath::at(double t) const {
  if (!samples_.empty()) {
    if (t <= 0) return samples_.front().T_wc;
    if (t >= duration_) return samples_.back().T_wc;
    auto it = std::upper_bound(samples_.begin(), samples_.end(), t,
                               [](double v, const StampedPose& s) { return v < s.stamp; });
    const StampedPose& b = *it;
    const StampedPose& a = *(it - 1);
    double w = (t - a.stamp) / (b.stamp - a.stamp);
    Eigen::Quaterniond qa(a.T_wc.linear()), qb(b.T_wc.linear());
    Pose T = Pose::Identity();
    T.linear() = qa.slerp(w, qb).toRotationMatrix();
    T.translation() = (1 - w) * a.T_wc.translation() + w * b.T_wc.translation();
    return T;
  }
  // Built-in motions are offsets in the anchor's optical frame (x right, y down, z forward).
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  const double w = 2 * kPi;
  if (name_ == "static") {
    d = Eigen::Vector3d(0.002 * std::sin(w * t / 7.0), 0.0015 * std::sin(w * t / 5.3), 0.002 * std::sin(w * t / 9.1));
    R = rotXYZ(deg(0.2) * std::sin(w * t / 6.1), deg(0.3) * std::sin(w * t / 8.3), deg(0.15) * std::sin(w * t / 4.7));
  } else if (name_ == "xyz") {
    // Each axis in turn dominates, as in fr3 xyz, with a little of the others.
    d = Eigen::Vector3d(0.35 * std::sin(w * t / 10.0), 0.18 * std::sin(w * t / 6.5), 0.30 * std::sin(w * t / 13.0));
    R = rotXYZ(deg(2) * std::sin(w * t / 11.0), deg(3) * std::sin(w * t / 9.0), deg(1) * std::sin(w * t / 7.0));
  } else if (name_ == "rpy") {
    R = rotXYZ(deg(14) * std::sin(w * t / 8.0), deg(22) * std::sin(w * t / 10.0), deg(16) * std::sin(w * t / 6.0));
    d = Eigen::Vector3d(0.02 * std::sin(w * t / 9.0), 0.02 * std::sin(w * t / 7.0), 0.02 * std::sin(w * t / 11.0));
  } else if (name_ == "halfsphere") {
    // On a sphere of radius r about a centre r ahead, always looking at a point 2.5 m ahead.
    const double r = 0.5;
    double az = deg(70) * std::sin(w * t / 16.0);
    double el = deg(35) * std::sin(w * t / 11.0);
    Eigen::Vector3d c(0, 0, r);
    Eigen::Vector3d pos = c + r * Eigen::Vector3d(std::sin(az) * std::cos(el), std::sin(el), -std::cos(az) * std::cos(el));
    Pose L = lookAt(pos, Eigen::Vector3d(0, 0, 2.5), Eigen::Vector3d(0, -1, 0));
    return anchor_ * L;
  } else if (name_ == "loop") {
    // A circle of radius r about a centre r ahead, always facing the centre: the camera sweeps
    // the whole room once, comes back to its start pose at t = duration and goes on round, so
    // that a sequence longer than the duration revisits the start over several keyframes.
    const double r = 0.8;
    double a = w * std::max(t, 0.0) / duration_;
    Eigen::Vector3d pos(r * std::sin(a), 0.05 * std::sin(2 * a), r - r * std::cos(a));
    R = Eigen::AngleAxisd(a, -Eigen::Vector3d::UnitY()).toRotationMatrix();
    Pose T = Pose::Identity();
    T.linear() = R;
    T.translation() = pos;
    return anchor_ * T;
  }
  Pose T = Pose::Identity();
  T.linear() = R;
  T.translation() = d;
  return anchor_ * T;
}

}  // namespace sim
}  // namespace yolo_slam
