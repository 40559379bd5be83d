// Screening beyond the boxes: the grown person mask, the keypoints outside every box and those
// of a person behind a boxed one it drops, and the no-depth keypoints it keeps or drops
// (person_mask.h, Screening.growOutside, Screening.maskInBoxes, Screening.noDepthHoleRadius).
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/screening/person_mask.h"
#include "yolo_slam/screening/screener.h"

#include <gtest/gtest.h>

using namespace yolo_slam;
using namespace yolo_slam::screening;

namespace {

constexpr float kWall = 4.f, kPerson = 1.5f;

// A wall at 4 m; a person at 1.5 m over x 150-239, whose arm (rows 190-209) reaches out to
// x 309, past the box's right edge at x 250; a depth hole (no reading) below the arm at
// x 265-284, rows 215-234.
cv::Mat sceneDepth() {
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(kWall));
  depth(cv::Rect(150, 50, 90, 420)).setTo(kPerson);
  depth(cv::Rect(240, 190, 70, 20)).setTo(kPerson);
  depth(cv::Rect(265, 215, 20, 20)).setTo(0.f);
  return depth;
}

struct Scene {
  features::FeatureFrame frame;
  detection::Boxes boxes;
  int add(cv::Point2f p, float d) {
    frame.keypoints.emplace_back(p, 31.f);
    frame.depth.push_back(d);
    return static_cast<int>(frame.keypoints.size()) - 1;
  }
};

// The indices of the keypoints the tests look at.
struct Probe {
  int arm = 0, arm_past_limit = 0, hole_near = 0, hole_far = 0, box_hole = 0, wall_outside = 0;
};

// The person's keypoints in the box (x 100-249), some wall in the box, and the probes.
Scene makeScene(Probe& p) {
  Scene s;
  s.frame.width = 640;
  s.frame.height = 480;
  for (int x = 155; x <= 235; x += 20)
    for (int y = 80; y <= 440; y += 40) s.add(cv::Point2f(x, y), kPerson + 0.002f * (y / 40));
  s.add({152, 300}, kPerson);  // the person's left outline
  for (int y = 80; y <= 440; y += 90) s.add(cv::Point2f(110, y), kWall);
  p.arm = s.add({275, 200}, kPerson);             // on the arm, outside the dilated box
  p.arm_past_limit = s.add({305, 200}, kPerson);  // on the arm, past growOutside
  p.hole_near = s.add({275, 217}, 0.f);           // hole 8 px below the arm
  p.hole_far = s.add({275, 270}, 0.f);            // no depth, 36 px from the body
  p.box_hole = s.add({115, 300}, 0.f);            // in the box: 37 px from the outline keypoint,
                                                  // 35 px from the person's pixels
  p.wall_outside = s.add({400, 200}, kWall);
  s.frame.keypoints_un = s.frame.keypoints;
  s.boxes.resize(1);
  s.boxes[0].label = "person";
  s.boxes[0].score = 0.9f;
  s.boxes[0].rect = cv::Rect2f(100, 50, 150, 420);
  return s;
}

ScreeningStats screenScene(const ScreeningOptions& o, Scene& s) {
  return Screener(o).screen(s.frame, s.boxes, sceneDepth());
}

}  // namespace

TEST(PersonMask, GrowsOverContinuousDepthWithinTheLimit) {
  PersonSeeds person;
  person.pts = {{200, 200}};
  person.lo = kPerson - 0.1f;
  person.hi = kPerson + 0.1f;
  person.limit = cv::Rect2f(100, 0, 200, 480);  // x 100-299
  const cv::Mat mask = growPersonMask(sceneDepth(), {person});
  ASSERT_EQ(mask.size(), cv::Size(320, 240));
  const auto at = [&](int x, int y) { return mask.at<uint8_t>(y / kPersonMaskStride, x / kPersonMaskStride) != 0; };
  EXPECT_TRUE(at(160, 60));    // the whole body, from one seed
  EXPECT_TRUE(at(280, 200));   // the arm beyond the box
  EXPECT_FALSE(at(302, 200));  // the arm past the limit
  EXPECT_FALSE(at(120, 200));  // the wall
  EXPECT_FALSE(at(270, 220));  // the hole
  const cv::Mat distance = personDistance(mask);
  EXPECT_NEAR(distanceAt(distance, {275, 225}), 16.f, 2.f);
  EXPECT_EQ(distanceAt(distance, {200, 200}), 0.f);
}

TEST(PersonMask, StopsAtADepthStepInsideTheDepthRange) {
  // A chair 0.15 m behind the person touches it: inside the person's depth range, but the
  // step between neighbours is far above kPersonMaskStepPerM times the depth.
  cv::Mat depth = sceneDepth();
  depth(cv::Rect(100, 300, 50, 100)).setTo(kPerson + 0.15f);
  PersonSeeds person;
  person.pts = {{200, 200}};
  person.lo = kPerson - 0.2f;
  person.hi = kPerson + 0.2f;
  person.limit = cv::Rect2f(0, 0, 640, 480);
  const cv::Mat mask = growPersonMask(depth, {person});
  EXPECT_EQ(mask.at<uint8_t>(350 / kPersonMaskStride, 120 / kPersonMaskStride), 0);
  EXPECT_EQ(cv::countNonZero(personDistance(cv::Mat::zeros(10, 10, CV_8U)) < 1e6f), 0);  // no person: far
}

TEST(BeyondBoxes, DropsThePersonsKeypointsOutsideTheBox) {
  Probe p;
  Scene s = makeScene(p);
  const ScreeningOptions o;
  ASSERT_EQ(o.grow_outside, 0.25);
  ASSERT_EQ(o.no_depth_hole_radius_px, 20.0);
  const ScreeningStats st = screenScene(o, s);
  EXPECT_EQ(s.frame.dynamic[p.arm], 1);
  EXPECT_EQ(s.frame.dynamic[p.arm_past_limit], 0);
  EXPECT_EQ(s.frame.dynamic[p.hole_near], 1);
  EXPECT_EQ(s.frame.dynamic[p.hole_far], 0);
  EXPECT_EQ(s.frame.dynamic[p.wall_outside], 0);
  EXPECT_EQ(st.grown_outside, 1);
  EXPECT_EQ(st.depth_holes, 1);
  EXPECT_EQ(st.in_boxes, st.kept + st.dropped);  // the counts of the boxes are unchanged
  const Json j = st;
  EXPECT_EQ(j.at("grown_outside"), 1);
  EXPECT_EQ(j.at("depth_holes"), 1);
}

TEST(BeyondBoxes, NarrowsTheNearDynamicRuleToHolesNearThePerson) {
  Probe p;
  Scene s = makeScene(p);
  screenScene(ScreeningOptions(), s);
  EXPECT_EQ(s.frame.dynamic[p.box_hole], 0);  // 35 px from the person's pixels: background
  ScreeningOptions off;
  off.no_depth_hole_radius_px = 0;  // the near-dynamic rule alone: 37 px from a person keypoint
  Scene s2 = makeScene(p);
  const ScreeningStats st = screenScene(off, s2);
  EXPECT_EQ(s2.frame.dynamic[p.box_hole], 1);
  EXPECT_EQ(s2.frame.dynamic[p.arm], 0);
  EXPECT_EQ(s2.frame.dynamic[p.hole_near], 0);
  EXPECT_EQ(st.grown_outside + st.depth_holes, 0);
}

TEST(BeyondBoxes, OffWithoutGrowthOrDepthImage) {
  Probe p;
  ScreeningOptions o;
  o.grow_outside = 0;  // the mask stops at the dilated box: only the hole rule reaches out
  Scene s = makeScene(p);
  const ScreeningStats st = screenScene(o, s);
  EXPECT_EQ(s.frame.dynamic[p.arm], 0);
  EXPECT_EQ(st.grown_outside, 0);
  Scene s2 = makeScene(p);
  const ScreeningStats none = Screener(ScreeningOptions()).screen(s2.frame, s2.boxes);
  EXPECT_EQ(none.grown_outside + none.depth_holes, 0);
  EXPECT_EQ(s2.frame.dynamic[p.box_hole], 1);  // no depth image: the near-dynamic rule as before
}

namespace {

constexpr float kBehind = 2.5f;

// The wall at 4 m; a person at 1.5 m over x 150-239, boxed at x 100-249; a second person at
// 2.5 m over x 240-329 standing behind the first, whose own box (x 262-331) misses their left
// edge, x 240-258, which lies in the first person's dilated box (up to x 257.5).
struct TwoPeople {
  Scene scene;
  cv::Mat depth = cv::Mat(480, 640, CV_32F, cv::Scalar(kWall));
  int behind_in_front_box = 0, behind_in_front_box2 = 0, wall_in_front_box = 0;
  TwoPeople() {
    depth(cv::Rect(240, 60, 90, 400)).setTo(kBehind);
    depth(cv::Rect(150, 50, 90, 420)).setTo(kPerson);
    Scene& s = scene;
    s.frame.width = 640;
    s.frame.height = 480;
    for (int x = 155; x <= 235; x += 20)
      for (int y = 80; y <= 440; y += 40) s.add(cv::Point2f(x, y), kPerson);
    for (int x = 270; x <= 325; x += 15)
      for (int y = 80; y <= 440; y += 40) s.add(cv::Point2f(x, y), kBehind);
    behind_in_front_box = s.add({246, 200}, kBehind);
    behind_in_front_box2 = s.add({252, 320}, kBehind);
    wall_in_front_box = s.add({115, 200}, kWall);
    s.frame.keypoints_un = s.frame.keypoints;
    s.boxes.resize(2);
    s.boxes[0].rect = cv::Rect2f(100, 50, 150, 420);
    s.boxes[1].rect = cv::Rect2f(262, 60, 70, 400);
    for (auto& b : s.boxes) {
      b.label = "person";
      b.score = 0.9f;
    }
  }
};

}  // namespace

// A person standing behind the boxed one, beyond their own box: the front box's screening
// keeps them (its person is the front one), the mask grown from their own box reaches them.
TEST(BeyondBoxes, DropsAPersonBehindTheBoxedOneBeyondTheirOwnBox) {
  TwoPeople on;
  ScreeningOptions o;
  ASSERT_FALSE(o.mask_in_boxes);  // off by default
  o.mask_in_boxes = true;
  const ScreeningStats st = Screener(o).screen(on.scene.frame, on.scene.boxes, on.depth);
  EXPECT_EQ(on.scene.frame.dynamic[on.behind_in_front_box], 1);
  EXPECT_EQ(on.scene.frame.dynamic[on.behind_in_front_box2], 1);
  EXPECT_EQ(on.scene.frame.dynamic[on.wall_in_front_box], 0);
  EXPECT_EQ(st.grown_in_boxes, 2);
  EXPECT_EQ(Json(st).at("grown_in_boxes"), 2);

  const ScreeningOptions off;
  TwoPeople without;
  const ScreeningStats st_off = Screener(off).screen(without.scene.frame, without.scene.boxes, without.depth);
  EXPECT_EQ(without.scene.frame.dynamic[without.behind_in_front_box], 0);
  EXPECT_EQ(without.scene.frame.dynamic[without.behind_in_front_box2], 0);
  EXPECT_EQ(st_off.grown_in_boxes, 0);
  EXPECT_EQ(st.dropped, st_off.dropped + 2);
}

TEST(BeyondBoxes, OptionsLoadAndValidate) {
  const ScreeningOptions o = ScreeningOptions::load(
      Config::fromString("Screening.growOutside: 0.5\nScreening.noDepthHoleRadius: 8\n"
                         "Screening.maskInBoxes: 1\n", "s.yaml"));
  EXPECT_EQ(o.grow_outside, 0.5);
  EXPECT_TRUE(o.mask_in_boxes);
  EXPECT_EQ(o.no_depth_hole_radius_px, 8.0);
  EXPECT_THROW(ScreeningOptions::load(Config::fromString("Screening.growOutside: -0.1\n", "s.yaml")), Error);
  EXPECT_THROW(ScreeningOptions::load(Config::fromString("Screening.growOutside: 1.5\n", "s.yaml")), Error);
  EXPECT_THROW(ScreeningOptions::load(Config::fromString("Screening.noDepthHoleRadius: -1\n", "s.yaml")), Error);
  ScreeningOptions bad;
  bad.grow_outside = 2;
  EXPECT_THROW(bad.validate(), Error);
}
