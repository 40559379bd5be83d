#pragma once
// ORB descriptor matching for tracking and mapping (ORB-SLAM2 ORBmatcher equivalents). All
// functions read/write map objects: the caller holds Map::update_mutex.
#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/types.h"

#include <utility>
#include <vector>

namespace yolo_slam {
namespace slam {

class Map;

namespace matcher {

// Hamming distance bounds of a descriptor match: TH_HIGH for projection searches, TH_LOW for
// BoW, triangulation and fusion.
constexpr int kThHigh = features::kOrbHammingHigh;
constexpr int kThLow = features::kOrbHammingLow;
// searchProjections reports a map point as on a moving object only if the dynamic keypoint it
// matches is within this fraction of the point's predicted depth (a nearer keypoint hides it).
constexpr double kDynamicDepthTolerance = 0.1;

// A map point projected into a frame (ORB-SLAM2 isInFrustum results).
struct Projection {
  MapPointPtr mp;
  double u = 0, v = 0, ur = -1;  // pixel, virtual right coordinate
  double z = -1;                 // predicted depth in the frame (m); <= 0 unknown
  int level = 0;                 // predicted pyramid level
  double view_cos = 1;           // cosine between viewing ray and the point's mean normal
};

// Projects `mp` with frame F's pose; false if behind, outside the image, outside the scale
// range or seen at more than acos(min_view_cos) from its mean viewing direction.
bool projectInFrame(const Frame& F, const MapPointPtr& mp, double min_view_cos, Projection& out);

// Motion-model search (ORB-SLAM2 SearchByProjection(Frame, LastFrame)): projects the last
// frame's points with F's predicted pose into a window th * scale(octave), checks the virtual
// right coordinate and the rotation consistency. Returns matches written into F.points.
int searchLastFrame(Frame& F, const Frame& last, double th);

// Local-map search (ORB-SLAM2 SearchByProjection(Frame, vector<MapPoint*>)): radius th *
// (2.5 or 4 by viewing angle) * scale(predicted level), ratio test between the two best
// distances when on the same level. Points whose best candidate is a *dynamic* keypoint at
// their own depth (within kDynamicDepthTolerance, or without depth) that the frame-to-frame
// test saw move (Frame::motion 0; any dynamic keypoint when the test did not run) are
// appended to `dynamic_hits` (if given) instead of being matched.
//
// `dropped` (if given, and the frame-to-frame test ran): a point seen by at least
// `min_observations` keyframes that finds no static keypoint may match a dynamic keypoint the
// test did not see move (Frame::motion 1 or -1) at its own depth (or without depth), within
// kThLow and the ratio test: background the screening dropped inside a person's box matches its
// own point. The keypoint becomes static (Frame::dynamic 0) and its index is appended to
// `matched`; the caller puts it back when the pose calls it an outlier.
struct DroppedMatching {
  int min_observations = 0;  // 0: off
  std::vector<int>* matched = nullptr;
};
int searchProjections(Frame& F, const std::vector<Projection>& proj, double th, double nn_ratio,
                      std::vector<MapPointPtr>* dynamic_hits = nullptr,
                      const DroppedMatching* dropped = nullptr);

// BoW search between a keyframe and a frame (ORB-SLAM2 SearchByBoW, vocabulary::searchByBow):
// the keyframe's keypoints with a good static map point against F's static keypoints; requires
// both BoW slots filled. Matches written into F.points; returns their number.
int searchByBow(const KeyFrame& kf, Frame& F, double nn_ratio = 0.7);

// Candidate pairs (idx1, idx2) for triangulation between two keyframes: unmatched static
// keypoints, Hamming <= kThLow, within the epipolar band of F12 (x2^T F12 x1 = 0), consistent
// rotation.
std::vector<std::pair<size_t, size_t>> searchForTriangulation(const KeyFrame& kf1,
                                                              const KeyFrame& kf2,
                                                              const Eigen::Matrix3d& F12);

// Projects `points` into `kf` and fuses duplicates (ORB-SLAM2 Fuse): the point with fewer
// observations is replaced by the other, or a new observation is added. Returns fused count.
int fuse(Map& map, const KeyFramePtr& kf, const std::vector<MapPointPtr>& points, double th = 3.0);

}  // namespace matcher
}  // namespace slam
}  // namespace yolo_slam
