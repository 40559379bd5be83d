// The dense static map on constructed scenes: a box that moves in front of a wall leaves no
// occupied voxel where it stood; a pose correction moves the map; the person's pixels leave the
// static mask; the files load back (octomap's reader, the PLY reader); bad input is an Error.
#include "yolo_slam/common/error.h"
#include "yolo_slam/mapping/dense_map.h"
#include "yolo_slam/mapping/dense_mapper.h"
#include "yolo_slam/mapping/static_mask.h"

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>

using namespace yolo_slam;
using namespace yolo_slam::mapping;

namespace {

constexpr float kWallZ = 3.0f, kBoxZ = 1.5f;

CameraModel smallCamera() {
  CameraModel c;
  c.width = 160;
  c.height = 120;
  c.fx = c.fy = 200;
  c.cx = 80;
  c.cy = 60;
  return c;
}

// A wall at kWallZ filling the view, and a box at kBoxZ over the pixel rectangle `box`.
cv::Mat wallWithBox(const CameraModel& c, const cv::Rect& box) {
  cv::Mat d(c.height, c.width, CV_32FC1, cv::Scalar(kWallZ));
  if (!box.empty()) d(box).setTo(kBoxZ);
  return d;
}

cv::Mat allStatic(const cv::Mat& depth) { return cv::Mat(depth.size(), CV_8UC1, cv::Scalar(255)); }

DenseMapOptions testOptions() {
  DenseMapOptions o;
  o.enabled = true;
  o.resolution_m = 0.05;
  o.max_range_m = 4.0;  // the wall at 3 m is within range off the optical axis too
  o.pixel_stride = 2;
  o.final_rebuild = false;
  return o;
}

// Occupied finest voxels with centre inside the axis-aligned box [lo, hi].
int occupiedIn(const std::vector<Eigen::Vector3d>& centres, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  int n = 0;
  for (const auto& c : centres) n += (c.array() >= lo.array()).all() && (c.array() <= hi.array()).all();
  return n;
}

// The world region a pixel rectangle at depth z covers (camera at the origin), padded by pad.
std::pair<Eigen::Vector3d, Eigen::Vector3d> regionOf(const CameraModel& c, const cv::Rect& r, double z, double pad) {
  const Eigen::Vector3d a = c.unproject(r.x, r.y, z), b = c.unproject(r.br().x, r.br().y, z);
  return {a - Eigen::Vector3d::Constant(pad), b + Eigen::Vector3d::Constant(pad)};
}

std::string tempPath(const std::string& name) {
  return "/tmp/ys_dense_" + std::to_string(::getpid()) + "_" + name;
}

}  // namespace

TEST(DenseMap, AMovedBoxLeavesNoOccupiedVoxels) {
  const CameraModel cam = smallCamera();
  DenseMap map(cam, testOptions());
  const cv::Rect before(20, 40, 30, 30), after(110, 40, 30, 30);
  for (int k = 0; k < 5; ++k) {
    const cv::Mat d = wallWithBox(cam, before);
    map.integrate(backProject(cam, map.options(), cv::Mat(), d, allStatic(d)), Pose::Identity());
  }
  const auto r_before = regionOf(cam, before, kBoxZ, 0.03);
  ASSERT_GT(occupiedIn(map.occupiedCentres(), r_before.first, r_before.second), 0) << "the box was never mapped";
  for (int k = 0; k < 15; ++k) {
    const cv::Mat d = wallWithBox(cam, after);
    map.integrate(backProject(cam, map.options(), cv::Mat(), d, allStatic(d)), Pose::Identity());
  }
  const auto occ = map.occupiedCentres();
  EXPECT_EQ(occupiedIn(occ, r_before.first, r_before.second), 0) << "the box left a ghost";
  const auto r_after = regionOf(cam, after, kBoxZ, 0.03);
  EXPECT_GT(occupiedIn(occ, r_after.first, r_after.second), 0);
  // The wall behind the box's first place is mapped.
  const auto r_wall = regionOf(cam, before, kWallZ, 0.03);
  EXPECT_GT(occupiedIn(occ, r_wall.first, r_wall.second), 0);
  EXPECT_GT(map.cloud().size(), 0u);
}

TEST(DenseMap, MaskedPixelsAreNotIntegrated) {
  const CameraModel cam = smallCamera();
  DenseMap map(cam, testOptions());
  const cv::Rect box(20, 40, 30, 30);
  const cv::Mat d = wallWithBox(cam, box);
  cv::Mat mask = allStatic(d);
  mask(box).setTo(0);
  map.integrate(backProject(cam, map.options(), cv::Mat(), d, mask), Pose::Identity());
  const auto r = regionOf(cam, box, kBoxZ, 0.03);
  EXPECT_EQ(occupiedIn(map.occupiedCentres(), r.first, r.second), 0);
}

TEST(DenseMapper, ReintegratesAfterAPoseCorrection) {
  const CameraModel cam = smallCamera();
  Pose T_wc = Pose::Identity();
  long version = 0;
  DenseMapper mapper(cam, testOptions(), screening::ScreeningOptions(), false, [&] { return version; });
  for (int k = 0; k < 3; ++k) {
    DenseKeyFrame kf;
    kf.id = k;
    kf.pose = [&]() -> std::optional<Pose> { return T_wc; };
    kf.depth_m = wallWithBox(cam, cv::Rect());
    mapper.insert(kf);
  }
  mapper.processQueued();
  const double half = 0.3;
  const Eigen::Vector3d lo(-half, -half, kWallZ - 0.1), hi(half, half, kWallZ + 0.1);
  const Eigen::Vector3d shift(0, 0, 0.5);
  ASSERT_GT(occupiedIn(mapper.occupiedCentres(), lo, hi), 0);
  T_wc.translation() = shift;  // a loop closure moved every keyframe half a metre
  mapper.processQueued();
  EXPECT_GT(occupiedIn(mapper.occupiedCentres(), lo, hi), 0) << "rebuilt without a version change";
  ++version;
  mapper.processQueued();
  const auto occ = mapper.occupiedCentres();
  EXPECT_EQ(occupiedIn(occ, lo, hi), 0) << "the wall stayed at its old place";
  EXPECT_GT(occupiedIn(occ, lo + shift, hi + shift), 0);
  EXPECT_EQ(mapper.stats().rebuilds, 1u);
}

TEST(DenseMapper, ClearForgetsKeyFramesAndAGoneKeyFrameIsSkipped) {
  const CameraModel cam = smallCamera();
  DenseMapper mapper(cam, testOptions(), screening::ScreeningOptions(), false, nullptr);
  DenseKeyFrame gone;
  gone.pose = []() -> std::optional<Pose> { return std::nullopt; };
  gone.depth_m = wallWithBox(cam, cv::Rect());
  mapper.insert(gone);
  mapper.processQueued();
  EXPECT_EQ(mapper.stats().keyframes, 0u);
  DenseKeyFrame kf = gone;
  kf.pose = []() -> std::optional<Pose> { return Pose::Identity(); };
  mapper.insert(kf);
  mapper.processQueued();
  EXPECT_EQ(mapper.stats().keyframes, 1u);
  EXPECT_GT(mapper.stats().voxels, 0u);
  mapper.clear();
  EXPECT_EQ(mapper.stats().voxels, 0u);
}

TEST(DenseMapper, AThreadedMapperIntegratesEveryKeyFrameByStop) {
  const CameraModel cam = smallCamera();
  DenseMapOptions o = testOptions();
  o.final_rebuild = true;
  DenseMapper mapper(cam, o, screening::ScreeningOptions(), true, nullptr);
  mapper.start();
  for (int k = 0; k < 4; ++k) {
    DenseKeyFrame kf;
    kf.id = k;
    kf.pose = []() -> std::optional<Pose> { return Pose::Identity(); };
    kf.depth_m = wallWithBox(cam, cv::Rect());
    mapper.insert(kf);
  }
  mapper.stop();
  const DenseMapStats s = mapper.stats();
  EXPECT_EQ(s.keyframes + s.dropped, 4u);
  EXPECT_EQ(s.rebuilds, 1u);
  EXPECT_GT(s.voxels, 0u);
}

// ---- static mask -----------------------------------------------------------------------

namespace {
// A person (a rectangle at kBoxZ, its lower half at a depth gradient like a tilted body) in
// front of the wall, and its detection box around it with wall inside.
struct PersonScene {
  cv::Rect person{60, 20, 30, 80};
  detection::Box box;
  cv::Mat depth;
};

PersonScene personScene(const CameraModel& cam) {
  PersonScene s;
  s.depth = wallWithBox(cam, s.person);
  for (int v = s.person.y + s.person.height / 2; v < s.person.br().y; ++v)
    s.depth(cv::Rect(s.person.x, v, s.person.width, 1)).setTo(kBoxZ + 0.004f * (v - s.person.y));
  s.box.rect = cv::Rect2f(45, 12, 60, 96);
  s.box.label = "person";
  s.box.score = 1.f;
  return s;
}

int countValue(const cv::Mat& m, const cv::Rect& r, uint8_t v) { return cv::countNonZero(m(r) == v); }
}  // namespace

TEST(StaticMask, RemovesThePersonNotTheWallInItsBox) {
  const CameraModel cam = smallCamera();
  const PersonScene s = personScene(cam);
  screening::ScreeningOptions so;
  StaticMaskOptions mo;
  mo.margin_px = 2;
  const cv::Mat mask = staticMask(s.depth, {s.box}, screening::Screener(so), mo);
  EXPECT_EQ(countValue(mask, s.person, 255), 0) << "person pixels left static";
  // The wall inside the box, beyond the margin, stays static.
  const cv::Rect wall_left(46, 14, 10, 90);
  EXPECT_EQ(countValue(mask, wall_left, 0), 0) << "wall pixels removed";
}

TEST(StaticMask, FollowsTheScreeningMode) {
  const CameraModel cam = smallCamera();
  const PersonScene s = personScene(cam);
  screening::ScreeningOptions so;
  StaticMaskOptions mo;
  mo.margin_px = 0;
  so.mode = screening::DynamicMode::Off;
  EXPECT_EQ(cv::countNonZero(staticMask(s.depth, {s.box}, screening::Screener(so), mo) == 0), 0);
  so.mode = screening::DynamicMode::Detect;
  const cv::Mat detect = staticMask(s.depth, {s.box}, screening::Screener(so), mo);
  EXPECT_EQ(countValue(detect, cv::Rect(s.box.rect), 255), 0) << "detect mode removes the whole box";
  EXPECT_THROW(staticMask(cv::Mat(10, 10, CV_8UC1), {}, screening::Screener(so), mo), Error);
}

// ---- files and bad input ---------------------------------------------------------------

TEST(DenseMapFiles, OctomapAndPlyLoadBack) {
  const CameraModel cam = smallCamera();
  DenseMap map(cam, testOptions());
  const cv::Mat d = wallWithBox(cam, cv::Rect(20, 40, 30, 30));
  cv::Mat colour(d.size(), CV_8UC3, cv::Scalar(10, 20, 30));
  map.integrate(backProject(cam, map.options(), colour, d, allStatic(d)), Pose::Identity());
  const std::string bt = tempPath("map.bt"), ply = tempPath("cloud.ply");
  map.writeOctomap(bt);
  octomap::OcTree read(0.1);
  ASSERT_TRUE(read.readBinary(bt));
  EXPECT_DOUBLE_EQ(read.getResolution(), 0.05);
  double res = 0;
  EXPECT_EQ(readOctomapOccupied(bt, &res).size(), map.occupiedVoxels());
  const auto cloud = map.cloud();
  ASSERT_FALSE(cloud.empty());
  writePly(ply, cloud);
  const auto back = readPly(ply);
  ASSERT_EQ(back.size(), cloud.size());
  EXPECT_EQ(back[0].p, cloud[0].p);
  // Camera.RGB 1 by default: the image is RGB, so the first channel is red.
  EXPECT_EQ(back[0].rgb, (std::array<uint8_t, 3>{10, 20, 30}));
  std::remove(bt.c_str());
  std::remove(ply.c_str());
}

TEST(DenseMapFiles, BadFilesAndInputsNameTheProblem) {
  const std::string bad = tempPath("bad.ply");
  { std::ofstream(bad) << "ply\nformat binary_big_endian 1.0\nend_header\n"; }
  try {
    readPly(bad);
    FAIL() << "a big-endian PLY was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  EXPECT_THROW(readOctomapOccupied(bad), Error);
  EXPECT_THROW(readPly(tempPath("missing.ply")), Error);
  std::remove(bad.c_str());
  const CameraModel cam = smallCamera();
  const cv::Mat d = wallWithBox(cam, cv::Rect());
  EXPECT_THROW(backProject(cam, testOptions(), cv::Mat(), d, cv::Mat(5, 5, CV_8UC1)), Error);
  DenseMapOptions o = testOptions();
  o.resolution_m = 0;
  EXPECT_THROW(DenseMap(cam, o), Error);
}

TEST(OccupancyGrid, TheHeightBandDecidesWhatBlocksACell) {
  const double r = 0.1;
  const std::vector<Voxel> occupied = {{{0.05, 0.05, 0.5}, r}, {{0.35, 0.05, 2.5}, r}};  // a wall; a lamp above the band
  const std::vector<Voxel> free = {{{0.2, 0.2, 0.4}, 0.4}};                                 // a pruned free leaf
  const OccupancyGrid2D g = projectToGrid(occupied, free, 0.1, 1.5, r);
  ASSERT_EQ(g.width, 4);
  ASSERT_EQ(g.height, 4);
  EXPECT_NEAR(g.origin_x, 0.0, 1e-9);
  EXPECT_EQ(g.cells[0], OccupancyGrid2D::kOccupied);
  EXPECT_EQ(g.cells[3], OccupancyGrid2D::kFree) << "the lamp is above the band";
  EXPECT_EQ(g.cells[5], OccupancyGrid2D::kFree);
  EXPECT_TRUE(projectToGrid(occupied, free, 3.0, 4.0, r).cells.empty());
}
