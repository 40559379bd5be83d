#pragma once
// The young-point check (Tracking.youngPointCheck, beyond ORB-SLAM2). A keyframe makes map
// points from the depth of its static keypoints; a person the screening missed in that frame
// is in the map at once, and with depth and near the camera those points outweigh the far
// static scene: the next frames' poses follow the person (the crowd preset's single-frame
// spikes of 40-100 mm). A point is "young" until the map has had a few keyframes to confirm it;
// young matches that disagree with the pose the confirmed matches give alone are released.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/optimization/pose_optimizer.h"
#include "yolo_slam/slam/types.h"

#include <functional>

namespace yolo_slam {
namespace slam {

class Frame;

// Keyframes after the one that made a point during which the point stays young.
constexpr long kYoungKeyFrames = 2;
// The check runs when at least kYoungMinTested young matches are inliers and at least
// kYoungMinConfirmed confirmed ones remain inliers of the pose they give alone.
constexpr int kYoungMinTested = 10;
constexpr int kYoungMinConfirmed = 30;

// Young: observed by one keyframe only, or made by one of the last kYoungKeyFrames + 1
// keyframes (last_kf_id and those before it); never a point of the map's first keyframe
// (init_kf_id, -1 for none), which is what the first keyframes are checked against.
bool isYoung(const MapPoint& mp, long last_kf_id, long init_kf_id);

// For F's inlier matches (not outliers, not dynamic keypoints, points with observations): the
// pose of the confirmed matches alone (pose optimisation from F's pose, with `prior` if not
// null); then each young match whose chi2 there exceeds the 95 % bound is released (F.points
// reset). F's pose is left as it was. Returns the matches released (0 when too few to test).
int releaseDisagreeingYoung(const CameraModel& cam, Frame& F, const std::function<bool(const MapPoint&)>& young,
                            const optimization::PosePrior* prior);

}  // namespace slam
}  // namespace yolo_slam
