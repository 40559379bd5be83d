// Local-map search and dynamic keypoints (matcher::searchProjections): a map point whose best
// match is a dynamic keypoint at its own depth lies on a moving object and is reported; one
// hidden behind a nearer dynamic keypoint (a person walking in front of the wall) is not, nor
// one matching a dropped keypoint that the frame-to-frame test found static. With
// DroppedMatching (Tracking.droppedMapMatches) such a point seen by enough keyframes matches
// that keypoint, which becomes static.
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/slam/matcher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace yolo_slam;
using namespace yolo_slam::slam;
using namespace yolo_slam::slam::matcher;

namespace {

constexpr float kU = 320, kV = 240;

// The map point's depth and predicted virtual right coordinate u - bf / z.
double pointDepth() { return 2.0; }
double virtualRight(double z) { return kU - CameraModel().bf / z; }

cv::Mat randomDescriptor(unsigned seed) {
  std::mt19937 rng(seed);
  cv::Mat d(1, 32, CV_8U);
  for (int b = 0; b < 32; ++b) d.at<uint8_t>(0, b) = static_cast<uint8_t>(rng());
  return d;
}

// One keypoint at (kU, kV) carrying `desc`, dynamic or not, at depth `z` (<= 0: no depth), plus
// a few unrelated static keypoints elsewhere.
Frame makeFrame(const cv::Mat& desc, bool dynamic, double z) {
  features::FeatureFrame ff;
  ff.width = 640;
  ff.height = 480;
  ff.descriptors = cv::Mat(0, 32, CV_8U);
  auto add = [&](cv::Point2f pt, const cv::Mat& d, bool dyn, double depth) {
    cv::KeyPoint kp(pt, 31.f);
    kp.octave = 0;
    ff.keypoints.push_back(kp);
    ff.descriptors.push_back(d);
    ff.depth.push_back(depth > 0 ? static_cast<float>(depth) : 0.f);
    ff.right_u.push_back(depth > 0 ? static_cast<float>(pt.x - CameraModel().bf / depth) : -1.f);
    ff.dynamic.push_back(dyn ? 1 : 0);
  };
  add(cv::Point2f(kU, kV), desc, dynamic, z);
  for (unsigned k = 0; k < 4; ++k)
    add(cv::Point2f(100.f + 100.f * k, 100.f), randomDescriptor(100 + k), false, 3.0);
  ff.keypoints_un = ff.keypoints;
  CameraModel cam;
  auto pyr = std::make_shared<ScalePyramid>(ScalePyramid::make(8, 1.2));
  Frame f(ff, cam, FrameGeometry::make(cam), pyr, 1);
  f.setPose(Pose::Identity());
  return f;
}

struct Result {
  int matched = 0;
  size_t dynamic_hits = 0;
};

Result search(Frame& F, const cv::Mat& desc, int observations = 0, const DroppedMatching* dropped = nullptr) {
  auto mp = std::make_shared<MapPoint>(1, Eigen::Vector3d(0, 0, 2), nullptr, 0);
  std::vector<KeyFramePtr> kfs;  // keep the observing keyframes alive through the search
  for (int k = 0; k < observations; ++k) {
    kfs.push_back(std::make_shared<KeyFrame>(k + 1, F));
    Map::addObservation(mp, kfs.back(), 0);
  }
  mp->descriptor = desc.clone();
  Projection p;
  p.mp = mp;
  p.u = kU;
  p.v = kV;
  p.ur = virtualRight(pointDepth());
  p.z = pointDepth();
  p.level = 0;
  std::vector<MapPointPtr> hits;
  Result r;
  r.matched = searchProjections(F, {p}, 1.0, 0.8, &hits, dropped);
  r.dynamic_hits = hits.size();
  return r;
}

}  // namespace

TEST(MatcherDynamic, PointOnAMovingObjectIsReported) {
  const cv::Mat d = randomDescriptor(7);
  Frame F = makeFrame(d, true, pointDepth() * 1.05);  // on the point's surface
  const Result r = search(F, d);
  EXPECT_EQ(r.dynamic_hits, 1u);
  EXPECT_EQ(r.matched, 0);
}

TEST(MatcherDynamic, PointHiddenBehindANearerDynamicKeypointIsNotReported) {
  const cv::Mat d = randomDescriptor(7);
  // The dynamic keypoint is 0.5 m nearer than the map point: its virtual right coordinate lies
  // only a few pixels from the point's prediction, inside the search radius.
  Frame F = makeFrame(d, true, pointDepth() - 0.5);
  EXPECT_LT(std::fabs(F.right_u[0] - virtualRight(pointDepth())), 7.0);
  const Result r = search(F, d);
  EXPECT_EQ(r.dynamic_hits, 0u);
  EXPECT_EQ(r.matched, 0);  // and a dynamic keypoint is never matched
}

TEST(MatcherDynamic, DroppedKeypointThatDidNotMoveIsNotReported) {
  const cv::Mat d = randomDescriptor(7);
  // Screening dropped it (inside a person's box) but the frame-to-frame test found it where a
  // static point would be: background, not a moving object.
  Frame F = makeFrame(d, true, pointDepth());
  F.motion.assign(F.N, -1);
  F.motion[0] = 1;
  EXPECT_EQ(search(F, d).dynamic_hits, 0u);
  F.motion[0] = -1;  // untested (no match in the previous frame): no evidence either
  EXPECT_EQ(search(F, d).dynamic_hits, 0u);
  F.motion[0] = 0;  // it moved
  EXPECT_EQ(search(F, d).dynamic_hits, 1u);
}

// Without the frame-to-frame test (Frame::motion empty) every dynamic match counts.
TEST(MatcherDynamic, DynamicKeypointWithoutDepthStillCounts) {
  const cv::Mat d = randomDescriptor(7);
  Frame F = makeFrame(d, true, -1.0);
  EXPECT_EQ(search(F, d).dynamic_hits, 1u);
}

TEST(MatcherDynamic, StaticKeypointAtTheProjectionIsMatched) {
  const cv::Mat d = randomDescriptor(7);
  Frame F = makeFrame(d, false, pointDepth());
  const Result r = search(F, d);
  EXPECT_EQ(r.dynamic_hits, 0u);
  EXPECT_EQ(r.matched, 1);
  EXPECT_TRUE(F.points[0] != nullptr);
}

namespace {

// The dropped keypoint at the projection, not seen moving (`motion`), at depth `z`; the point
// seen by `observations` keyframes; DroppedMatching asking for `min_observations`.
struct DroppedCase {
  int motion = 1;
  double z = pointDepth();
  int observations = 3;
  int min_observations = 3;
};

struct DroppedOutcome {
  int matched = 0;
  std::vector<int> now_static;
  bool keypoint_dynamic = true;
};

DroppedOutcome searchDropped(const DroppedCase& c) {
  const cv::Mat d = randomDescriptor(7);
  Frame F = makeFrame(d, true, c.z);
  F.motion.assign(F.N, -1);
  F.motion[0] = static_cast<int8_t>(c.motion);
  DroppedOutcome out;
  DroppedMatching dropped;
  dropped.min_observations = c.min_observations;
  dropped.matched = &out.now_static;
  out.matched = search(F, d, c.observations, &dropped).matched;
  out.keypoint_dynamic = F.dynamic[0] != 0;
  return out;
}

}  // namespace

TEST(MatcherDropped, KeypointNotSeenMovingMatchesAnEstablishedPoint) {
  for (int motion : {1, -1}) {
    DroppedCase c;
    c.motion = motion;
    const DroppedOutcome o = searchDropped(c);
    EXPECT_EQ(o.matched, 1) << "motion " << motion;
    EXPECT_EQ(o.now_static, std::vector<int>{0});
    EXPECT_FALSE(o.keypoint_dynamic);
  }
  DroppedCase no_depth;
  no_depth.z = -1.0;  // far room beyond the sensor's range: the descriptor decides
  EXPECT_EQ(searchDropped(no_depth).matched, 1);
}

TEST(MatcherDropped, MovedKeypointYoungPointOtherDepthOrOffStayDynamic) {
  DroppedCase moved;
  moved.motion = 0;
  DroppedCase young;
  young.observations = 2;
  DroppedCase nearer;
  nearer.z = pointDepth() - 0.5;  // a person in front of the point
  DroppedCase off;
  off.min_observations = 0;
  for (const DroppedCase& c : {moved, young, nearer, off}) {
    const DroppedOutcome o = searchDropped(c);
    EXPECT_EQ(o.matched, 0);
    EXPECT_TRUE(o.now_static.empty());
    EXPECT_TRUE(o.keypoint_dynamic);
  }
}
