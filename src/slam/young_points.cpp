#include "yolo_slam/slam/young_points.h"

#include "yolo_slam/optimization/reprojection.h"
#include "yolo_slam/optimization/se3.h"
#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/slam/observation.h"

#include <vector>

namespace yolo_slam {
namespace slam {

bool isYoung(const MapPoint& mp, long last_kf_id, long init_kf_id) {
  const int n_obs = mp.numObservations();
  if (n_obs < 1 || (init_kf_id >= 0 && mp.first_kf_id == init_kf_id)) return false;
  return n_obs == 1 || (last_kf_id >= 0 && mp.first_kf_id >= last_kf_id - kYoungKeyFrames);
}

int releaseDisagreeingYoung(const CameraModel& cam, Frame& F, const std::function<bool(const MapPoint&)>& young,
                            const optimization::PosePrior* prior) {
  std::vector<optimization::PoseObservation> confirmed;
  std::vector<int> tested;
  for (int i = 0; i < F.N; ++i) {
    const MapPointPtr& mp = F.points[i];
    if (!mp || F.outlier[i] || F.dynamic[i] || mp->numObservations() < 1) continue;
    if (young(*mp)) tested.push_back(i);
    else confirmed.push_back(poseObservation(F, i, mp->Xw));
  }
  if (static_cast<int>(tested.size()) < kYoungMinTested || static_cast<int>(confirmed.size()) < kYoungMinConfirmed)
    return 0;
  std::vector<bool> is_outlier;
  Pose T = F.T_cw;
  if (optimization::optimizePose(cam, T, confirmed, is_outlier, optimization::kPoseRounds, prior) < kYoungMinConfirmed ||
      !T.matrix().allFinite())
    return 0;
  const optimization::Intrinsics K = optimization::Intrinsics::from(cam);
  double pose[optimization::kPoseParams];
  optimization::poseToParams(T, pose);
  int released = 0;
  for (int i : tested) {
    const optimization::PoseObservation o = poseObservation(F, i, F.points[i]->Xw);
    const optimization::ReprojectionCheck c =
        optimization::checkReprojection(K, pose, o.Xw, o.uv, o.u_right, o.inv_sigma2);
    if (c.chi2 <= optimization::chi2Threshold(o.u_right) && c.depth > 0) continue;
    F.points[i].reset();
    F.outlier[i] = false;
    ++released;
  }
  return released;
}

}  // namespace slam
}  // namespace yolo_slam
