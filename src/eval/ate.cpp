#include "yolo_slam/eval/ate.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/io/association.h"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace yolo_slam {
namespace eval {

Pose alignRigid(const std::vector<Eigen::Vector3d>& model, const std::vector<Eigen::Vector3d>& data) {
  if (model.size() != data.size()) throw Error("alignRigid: point sets differ in size");
  if (model.size() < 2) throw Error("alignRigid: need at least 2 point pairs to align");
  const double n = static_cast<double>(model.size());
  Eigen::Vector3d mu_m = Eigen::Vector3d::Zero(), mu_d = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < model.size(); ++k) {
    mu_m += model[k];
    mu_d += data[k];
  }
  mu_m /= n;
  mu_d /= n;
  // M = sum (data - mu_d)(model - mu_m)^T = U D V^T; R = U S V^T maximises trace(R^T M).
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < model.size(); ++k) M += (data[k] - mu_d) * (model[k] - mu_m).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  // A reflection would fit better when the points are (nearly) planar or noisy; flip the
  // direction of the smallest singular value to get a proper rotation.
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) S(2, 2) = -1;
  Pose T = Pose::Identity();
  T.linear() = svd.matrixU() * S * svd.matrixV().transpose();
  T.translation() = mu_d - T.linear() * mu_m;
  return T;
}

Trajectory uniqueByStamp(const Trajectory& traj) {
  Trajectory t = traj;
  std::stable_sort(t.begin(), t.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  Trajectory out;
  for (const StampedPose& p : t) {
    if (!out.empty() && out.back().stamp == p.stamp) {
      out.back() = p;  // later line overrides, as a Python dict does
    } else {
      out.push_back(p);
    }
  }
  return out;
}

namespace {

// Refuses a trajectory with a position no camera reaches (see kMaxCoordinateM).
void checkCoordinates(const Trajectory& traj, const char* which) {
  for (const StampedPose& p : traj) {
    const Eigen::Vector3d t = p.T_wc.translation();
    if (t.allFinite() && t.cwiseAbs().maxCoeff() <= kMaxCoordinateM) continue;
    char buf[160];
    std::snprintf(buf, sizeof buf, "ATE: the %s pose at stamp %.6f is at (%.3g, %.3g, %.3g) m, beyond %.0e m", which,
                  p.stamp, t.x(), t.y(), t.z(), kMaxCoordinateM);
    throw Error(std::string(buf) + ": the file is corrupt or not in metres; fix or remove that line");
  }
}

}  // namespace

AteResult computeAte(const Trajectory& gt_in, const Trajectory& est_in, double max_diff,
                     double offset, const Pose* fixed_alignment) {
  if (gt_in.empty()) throw Error("ATE: the ground-truth trajectory has no poses");
  if (est_in.empty()) throw Error("ATE: the estimated trajectory has no poses");
  checkCoordinates(gt_in, "ground-truth");
  checkCoordinates(est_in, "estimated");
  const Trajectory gt = uniqueByStamp(gt_in);
  const Trajectory est = uniqueByStamp(est_in);
  std::vector<double> ta, tb;
  for (const auto& p : gt) ta.push_back(p.stamp);
  for (const auto& p : est) tb.push_back(p.stamp);
  const auto matches = io::associate(ta, tb, offset, max_diff);
  if (matches.size() < 2) {
    throw Error("ATE: only " + std::to_string(matches.size()) +
                " ground-truth/estimate timestamp pairs within " + std::to_string(max_diff) +
                " s (need >= 2); are these files of the same sequence? (if the clocks differ "
                "slightly: yolo_slam_eval ate --max-diff SECONDS)");
  }
  AteResult r;
  std::vector<Eigen::Vector3d> est_pos;
  for (const auto& m : matches) {
    r.gt_stamps.push_back(gt[m.first].stamp);
    r.est_stamps.push_back(est[m.second].stamp);
    r.gt_positions.push_back(gt[m.first].T_wc.translation());
    est_pos.push_back(est[m.second].T_wc.translation());
  }
  r.alignment = fixed_alignment ? *fixed_alignment : alignRigid(est_pos, r.gt_positions);
  for (size_t k = 0; k < est_pos.size(); ++k) {
    r.est_aligned.push_back(r.alignment * est_pos[k]);
    r.errors.push_back((r.est_aligned[k] - r.gt_positions[k]).norm());
  }
  r.stats = errorStats(r.errors);
  // Bounded coordinates keep this finite; a failed alignment would not.
  if (!r.alignment.matrix().allFinite() || !std::isfinite(r.stats.rmse))
    throw Error("ATE: the alignment of the estimate onto the ground truth failed (not finite); check both files");
  return r;
}

}  // namespace eval
}  // namespace yolo_slam
