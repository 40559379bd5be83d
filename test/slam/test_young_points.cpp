// The young-point check: matches of points a keyframe has just made that disagree with the pose
// of the confirmed points alone are released (a person the screening missed moves between the
// keyframe and this frame); young points on the static scene are kept.
#include "yolo_slam/slam/young_points.h"

#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_point.h"

#include <gtest/gtest.h>

#include <memory>
#include <set>

using namespace yolo_slam;
using namespace yolo_slam::slam;

namespace {

constexpr double kWallDepth = 4.0;       // metres: the confirmed points
constexpr double kPersonDepth = 2.0;     // metres: the person's young points
constexpr double kPersonStep = 0.05;     // metres the person moved since the keyframe (along x)
constexpr double kPoseOffset = 0.03;     // metres the starting pose is off (pulled by the person)

const CameraModel& camera() {
  static const CameraModel cam;
  return cam;
}

// One frame at the origin looking along +z: keypoint i observes points[i] (where a point moved
// by `moved` would project), with the point's depth as its measured depth.
struct Scene {
  std::shared_ptr<Map> map;  // owns the keyframes and points, and breaks their cycles at the end
  Frame F;
  KeyFramePtr kf;
  std::set<long> young_ids;
  std::set<int> person;  // keypoint indices on the moving person
};

struct Spot {
  Eigen::Vector3d X;
  Eigen::Vector3d moved;  // displacement since the keyframe
  bool young;
  bool person;
};

std::vector<Spot> spots(int confirmed, int young_static, int young_person) {
  const CameraModel& cam = camera();
  std::vector<Spot> s;
  for (int k = 0; k < confirmed; ++k)
    s.push_back({cam.unproject(30 + (k % 10) * 60, 30 + (k / 10) * 70, kWallDepth), Eigen::Vector3d::Zero(), false, false});
  for (int k = 0; k < young_static; ++k)
    s.push_back({cam.unproject(60 + (k % 10) * 55, 400 + (k / 10) * 30, 2.5), Eigen::Vector3d::Zero(), true, false});
  for (int k = 0; k < young_person; ++k)
    s.push_back({cam.unproject(250 + (k % 5) * 25, 150 + (k / 5) * 40, kPersonDepth), Eigen::Vector3d(kPersonStep, 0, 0),
                 true, true});
  return s;
}

Scene makeScene(const std::vector<Spot>& spots) {
  const CameraModel& cam = camera();
  features::FeatureFrame ff;
  ff.width = cam.width;
  ff.height = cam.height;
  for (const Spot& s : spots) {
    const Eigen::Vector3d seen = s.X + s.moved;
    const Eigen::Vector2d uv = cam.project(seen);
    cv::KeyPoint kp(cv::Point2f(static_cast<float>(uv.x()), static_cast<float>(uv.y())), 31.f);
    kp.octave = 0;
    ff.keypoints.push_back(kp);
    ff.depth.push_back(static_cast<float>(seen.z()));
    ff.right_u.push_back(static_cast<float>(uv.x() - cam.bf / seen.z()));
    ff.dynamic.push_back(0);
  }
  ff.keypoints_un = ff.keypoints;
  ff.descriptors = cv::Mat::zeros(static_cast<int>(ff.keypoints.size()), 32, CV_8U);
  auto pyr = std::make_shared<ScalePyramid>(ScalePyramid::make(8, 1.2));
  Scene scene;
  scene.F = Frame(ff, cam, FrameGeometry::make(cam), pyr, 10);
  scene.F.setPose(Pose::Identity());
  scene.map = std::make_shared<Map>();
  scene.kf = std::make_shared<KeyFrame>(1, scene.F);
  scene.map->addKeyFrame(scene.kf);
  for (size_t i = 0; i < spots.size(); ++i) {
    auto mp = std::make_shared<MapPoint>(static_cast<long>(i), spots[i].X, scene.kf.get(), 5);
    Map::addObservation(mp, scene.kf, i);
    scene.map->addMapPoint(mp);
    scene.F.points[i] = mp;
    if (spots[i].young) scene.young_ids.insert(mp->id);
    if (spots[i].person) scene.person.insert(static_cast<int>(i));
  }
  return scene;
}

int release(Scene& s) {
  return releaseDisagreeingYoung(camera(), s.F, [&](const MapPoint& mp) { return s.young_ids.count(mp.id) > 0; },
                                 nullptr);
}

}  // namespace

TEST(YoungPoints, ThePersonsYoungMatchesAreReleasedTheWallsKept) {
  Scene s = makeScene(spots(60, 20, 20));
  Pose start = Pose::Identity();
  start.translation() = Eigen::Vector3d(-kPoseOffset, 0, 0);
  s.F.setPose(start);
  EXPECT_EQ(release(s), 20);
  for (int i = 0; i < s.F.N; ++i) EXPECT_EQ(s.F.points[i] == nullptr, s.person.count(i) > 0) << "keypoint " << i;
  EXPECT_TRUE(s.F.T_cw.isApprox(start)) << "the pose is the caller's to refine";
}

TEST(YoungPoints, YoungPointsOnTheStaticSceneAreAllKept) {
  Scene s = makeScene(spots(60, 20, 0));
  EXPECT_EQ(release(s), 0);
  for (int i = 0; i < s.F.N; ++i) EXPECT_NE(s.F.points[i], nullptr);
}

TEST(YoungPoints, TooFewConfirmedOrYoungMatchesAreNotJudged) {
  Scene few_confirmed = makeScene(spots(kYoungMinConfirmed - 1, 20, 20));
  EXPECT_EQ(release(few_confirmed), 0);
  Scene few_young = makeScene(spots(60, 0, kYoungMinTested - 1));
  EXPECT_EQ(release(few_young), 0);
}

TEST(YoungPoints, OutliersAndDynamicKeypointsAreNotCounted) {
  Scene s = makeScene(spots(60, 0, 20));
  // Half the person's matches already outliers or dynamic: too few young ones left to judge.
  int k = 0;
  for (int i : s.person) {
    if (k % 2 == 0) s.F.outlier[i] = true;
    else if (k < 12) s.F.dynamic[i] = 1;
    ++k;
  }
  EXPECT_EQ(release(s), 0);
}

TEST(YoungPoints, IsYoungFollowsTheKeyFramesThatSawThePoint) {
  Scene s = makeScene(spots(1, 0, 0));
  MapPoint& mp = *s.F.points[0];  // made by keyframe 1, seen by it alone
  EXPECT_TRUE(isYoung(mp, 9, 0));
  EXPECT_FALSE(isYoung(mp, 9, 1)) << "the map's first keyframe's points are the reference";
  auto kf2 = std::make_shared<KeyFrame>(2, s.F);
  s.map->addKeyFrame(kf2);
  Map::addObservation(s.F.points[0], kf2, 0);
  EXPECT_TRUE(isYoung(mp, 1 + kYoungKeyFrames, 0)) << "seen twice but made within the last keyframes";
  EXPECT_FALSE(isYoung(mp, 2 + kYoungKeyFrames, 0));
}
