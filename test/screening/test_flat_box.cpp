// Flat-box rule (screening/flat_box.h) on constructed depth scenes under the synthetic camera
// (fx 535.4, fy 539.2, cx 320.1, cy 247.6): a picture flush with a wall, a person in front of
// the wall standing on the floor, a tilted wall; plus the real TUM frame's two people.
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/screening/flat_box.h"
#include "yolo_slam/screening/screener.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <functional>
#include <random>

using namespace yolo_slam;
using namespace yolo_slam::screening;

namespace {

constexpr double kFx = 535.4, kFy = 539.2, kCx = 320.1, kCy = 247.6;

// Depth of the plane n.X = d seen through pixel (u, v); <= 0 when the ray misses it.
double planeDepth(const cv::Vec3d& n, double d, double u, double v) {
  const cv::Vec3d r((u - kCx) / kFx, (v - kCy) / kFy, 1.0);
  const double nr = n.dot(r);
  return nr > 1e-9 ? d / nr : -1;
}

// Keypoints on a 16 px grid over the 640x480 image (offset so rows differ), depth from `scene`
// with the synthetic sensor's noise sigma = 0.0012 + 0.0019 (z - 0.4)^2 (fixed seed).
features::FeatureFrame makeFrame(const std::function<double(double, double)>& scene) {
  features::FeatureFrame f;
  f.width = 640;
  f.height = 480;
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int v = 5; v < 480; v += 16)
    for (int u = 3 + (v / 16 % 2) * 8; u < 640; u += 16) {
      double z = scene(u, v);
      if (z > 0) z += (0.0012 + 0.0019 * (z - 0.4) * (z - 0.4)) * noise(rng);
      f.keypoints.emplace_back(cv::Point2f(u, v), 31.f);
      f.depth.push_back(z > 0 ? static_cast<float>(z) : 0.f);
    }
  f.keypoints_un = f.keypoints;
  f.dynamic.assign(f.keypoints.size(), 0);
  return f;
}

detection::Boxes oneBox(const cv::Rect2f& r) {
  detection::Box b;
  b.label = "person";
  b.score = 0.6f;
  b.rect = r;
  return {b};
}

ScreeningOptions withRule(bool on) {
  ScreeningOptions o;  // defaults: detect+geometry, nearest, near-dynamic
  o.reject_flat_boxes = on;
  return o;
}

// Camera 0.8 m above a floor (y down), wall 3 m ahead; a person 0.5 m wide and 1.7 m tall at
// 2 m stands on the floor (image rect [253, 4, 134 x 459]), body relief 0.15 m.
const cv::Rect2f kPerson(253, 4, 134, 459);
double room(double u, double v) {
  const double wall = planeDepth({0, 0, 1}, 3.0, u, v);
  const double floor = planeDepth({0, 1, 0}, 0.8, u, v);
  return floor > 0 ? std::min(wall, floor) : wall;
}
double roomWithPerson(double u, double v) {
  if (!kPerson.contains(cv::Point2f(u, v))) return room(u, v);
  const double x = (u - (kPerson.x + kPerson.width / 2)) / (kPerson.width / 2);  // -1..1
  return 2.0 - 0.15 * std::sqrt(std::max(0.0, 1 - x * x));  // rounded body, nearest in the middle
}

}  // namespace

TEST(FlatBox, PlaneFitRecoversAPlaneDespiteOutliers) {
  const cv::Vec3d n = cv::normalize(cv::Vec3d(0.3, -0.2, 1.0));
  std::vector<cv::Point2f> pts;
  std::vector<float> depths;
  for (int i = 0; i < 60; ++i) {
    const float u = 50 + 9 * i % 500, v = 40 + 23 * i % 400;
    pts.emplace_back(u, v);
    depths.push_back(static_cast<float>(planeDepth(n, 2.0, u, v)));
  }
  for (int i = 0; i < 15; ++i) depths[4 * i] *= 0.7f;  // 25% outliers, 30% nearer
  InverseDepthPlane p;
  EXPECT_EQ(fitInverseDepthPlane(pts, depths, 1e-4, 0, p), 45);
  // 1/z = n.K^-1(u,v,1)/d: a = nx/(fx d), b = ny/(fy d).
  EXPECT_NEAR(p.a, n[0] / (kFx * 2.0), 1e-7);
  EXPECT_NEAR(p.b, n[1] / (kFy * 2.0), 1e-7);
  // Collinear pixels determine no plane.
  std::vector<cv::Point2f> line{{1, 1}, {2, 2}, {3, 3}, {4, 4}};
  std::vector<float> d4{1, 1, 1, 1};
  EXPECT_EQ(fitInverseDepthPlane(line, d4, 0.01, 0, p), 0);
}

TEST(FlatBox, PictureFlushWithWallIsRejectedNothingDropped) {
  // A fronto-parallel wall at 3 m fills the image; the "person" box lies on a picture on it.
  features::FeatureFrame frame = makeFrame([](double u, double v) { return planeDepth({0, 0, 1}, 3.0, u, v); });
  const detection::Boxes boxes = oneBox({220, 120, 150, 220});
  features::FeatureFrame without = frame;
  ScreeningStats off = Screener(withRule(false)).screen(without, boxes);
  EXPECT_GT(off.dropped, 50) << "without the rule the wall in the box is dropped";
  ScreeningStats on = Screener(withRule(true)).screen(frame, boxes);
  EXPECT_EQ(on.flat_boxes, 1);
  EXPECT_EQ(on.dropped, 0);
  EXPECT_EQ(frame.countDynamic(), 0u);
  EXPECT_GT(on.in_boxes, 50);
}

TEST(FlatBox, PersonInFrontOfWallIsNotRejectedAndDropped) {
  features::FeatureFrame frame = makeFrame(roomWithPerson);
  ScreeningStats st = Screener(withRule(true)).screen(frame, oneBox(kPerson));
  EXPECT_EQ(st.flat_boxes, 0);
  int person = 0, person_dropped = 0;
  for (size_t i = 0; i < frame.size(); ++i) {
    if (!kPerson.contains(frame.keypoints[i].pt)) continue;
    ++person;
    person_dropped += frame.dynamic[i];
  }
  EXPECT_GT(person, 100);
  EXPECT_EQ(person_dropped, person);
  // The test's numbers: the person's plane meets the ring only where the floor touches it.
  std::vector<int> cluster;
  for (size_t i = 0; i < frame.size(); ++i)
    if (frame.dynamic[i]) cluster.push_back(static_cast<int>(i));
  FlatBoxResult r = testFlatBox(frame, kPerson, cluster, FlatBoxOptions{});
  EXPECT_FALSE(r.flat);
  EXPECT_GT(r.ring_points, 50);
  EXPECT_LT(r.ringFraction(), 0.2);
}

TEST(FlatBox, PersonCloseToTheWallIsStillAPerson) {
  // 1 m in front of the wall (person at 2 m, wall at 3 m) is the case above; 0.5 m still holds.
  auto scene = [](double u, double v) {
    const double z = roomWithPerson(u, v);
    return kPerson.contains(cv::Point2f(u, v)) ? z + 0.5 : room(u, v);
  };
  features::FeatureFrame frame = makeFrame(scene);
  ScreeningStats st = Screener(withRule(true)).screen(frame, oneBox(kPerson));
  EXPECT_EQ(st.flat_boxes, 0);
  EXPECT_GT(st.dropped, 100);
}

TEST(FlatBox, NeighbouringPeopleAreNotTheSurroundings) {
  // Three people shoulder to shoulder at 2 m (flat cut-outs, 0.5 m apart): the middle box's
  // ring is half people on its plane; they are other boxes, not a wall continuing past it.
  const std::vector<cv::Rect2f> people{{119, 4, 134, 459}, kPerson, {387, 4, 134, 459}};
  auto scene = [&](double u, double v) {
    for (const auto& r : people)
      if (r.contains(cv::Point2f(u, v))) return 2.0;
    return room(u, v);
  };
  features::FeatureFrame frame = makeFrame(scene);
  detection::Boxes boxes;
  for (const auto& r : people) boxes.push_back(oneBox(r)[0]);
  std::vector<int> cluster;
  for (size_t i = 0; i < frame.size(); ++i)
    if (kPerson.contains(frame.keypoints[i].pt)) cluster.push_back(static_cast<int>(i));
  EXPECT_TRUE(testFlatBox(frame, kPerson, cluster, FlatBoxOptions{}).flat)
      << "without the other boxes left out, the neighbours look like a continuing surface";
  EXPECT_FALSE(testFlatBox(frame, kPerson, cluster, FlatBoxOptions{}, {people[0], people[2]}).flat);
  ScreeningStats st = Screener(withRule(true)).screen(frame, boxes);
  EXPECT_EQ(st.flat_boxes, 0);
}

TEST(FlatBox, TiltedWallIsStillFlat) {
  // Wall turned 50 degrees about the vertical axis (depth 1.7 m to 6 m across the image) with a
  // floor below: the box sits on the wall above the floor line.
  const cv::Vec3d n(std::sin(50 * CV_PI / 180), 0, std::cos(50 * CV_PI / 180));
  auto scene = [&](double u, double v) {
    const double wall = planeDepth(n, 2.5, u, v);
    const double floor = planeDepth({0, 1, 0}, 0.8, u, v);
    return floor > 0 && (wall <= 0 || floor < wall) ? floor : wall;
  };
  features::FeatureFrame frame = makeFrame(scene);
  const detection::Boxes boxes = oneBox({300, 40, 140, 170});
  ScreeningStats st = Screener(withRule(true)).screen(frame, boxes);
  EXPECT_EQ(st.flat_boxes, 1);
  EXPECT_EQ(st.dropped, 0);
}

TEST(FlatBox, OptionsLoadAndValidate) {
  Config cfg = Config::fromString(
      "%YAML:1.0\nScreening.rejectFlatBoxes: 1\nScreening.flatBoxFraction: 0.5\n"
      "Screening.flatBoxTolerance: 0.02\nScreening.flatBoxRing: 0.3\n",
      "flat.yaml");
  ScreeningOptions o = ScreeningOptions::load(cfg);
  EXPECT_TRUE(o.reject_flat_boxes);
  EXPECT_DOUBLE_EQ(o.flat_box_fraction, 0.5);
  EXPECT_DOUBLE_EQ(o.flat_box_tolerance, 0.02);
  EXPECT_DOUBLE_EQ(o.flat_box_ring, 0.3);
  for (const char* bad : {"Screening.flatBoxFraction: 0\n", "Screening.flatBoxTolerance: -1\n",
                          "Screening.flatBoxRing: 0\n"}) {
    try {
      ScreeningOptions::load(Config::fromString(std::string("%YAML:1.0\n") + bad, "bad.yaml"));
      ADD_FAILURE() << "accepted " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
    }
  }
}

TEST(FlatBox, RealTumPeopleAreNotRejected) {
  // fr3_walking_xyz frame 1341846313.592026: a standing person at ~1.3 m and a person sitting
  // at ~2 m in front of a desk and partition (boxes as in test_real_frame.cpp).
  const std::string dir = joinPath(sharedDir(), "data/tum/rgbd_dataset_freiburg3_walking_xyz");
  cv::Mat bgr = cv::imread(joinPath(dir, "rgb/1341846313.592026.png"), cv::IMREAD_COLOR);
  cv::Mat raw = cv::imread(joinPath(dir, "depth/1341846313.592088.png"), cv::IMREAD_ANYDEPTH);
  ASSERT_FALSE(bgr.empty() || raw.empty()) << "shared TUM frame missing? check YOLO_SLAM_SHARED";
  cv::Mat depth_m;
  raw.convertTo(depth_m, CV_32F, 1.0 / 5000.0);
  CameraModel cam;
  cam.rgb_order = false;
  features::OrbExtractor orb{features::OrbOptions{}};
  const features::FeatureFrame frame = features::buildFeatureFrame(orb, cam, bgr, depth_m, 0.0);
  detection::Boxes boxes = oneBox({473, 0, 167, 480});
  boxes.push_back(oneBox({35, 111, 210, 369})[0]);
  features::FeatureFrame a = frame, b = frame;
  ScreeningStats off = Screener(withRule(false)).screen(a, boxes);
  ScreeningStats on = Screener(withRule(true)).screen(b, boxes);
  EXPECT_EQ(on.flat_boxes, 0);
  EXPECT_EQ(on.dropped, off.dropped);
  EXPECT_GT(on.dropped, 300);
}
