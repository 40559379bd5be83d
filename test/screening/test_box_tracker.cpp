#include "yolo_slam/screening/box_tracker.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/screening/screener.h"

#include <gtest/gtest.h>

#include <functional>
#include <random>

using namespace yolo_slam;
using screening::BoxTracker;
using screening::BoxTrackerOptions;

namespace {

// A person: n textured keypoints inside `box` (fixed random descriptors), plus background
// keypoints spread over the image with their own descriptors.
struct Scene {
  std::vector<cv::Point2f> person, background;
  cv::Mat person_desc, background_desc;
};

Scene makeScene(const cv::Rect2f& box, int n_person, int n_background, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> ux(0.f, 1.f);
  Scene s;
  for (int i = 0; i < n_person; ++i)
    s.person.emplace_back(box.x + 5 + ux(rng) * (box.width - 10), box.y + 5 + ux(rng) * (box.height - 10));
  for (int i = 0; i < n_background; ++i) s.background.emplace_back(ux(rng) * 640, ux(rng) * 480);
  s.person_desc.create(n_person, 32, CV_8U);
  s.background_desc.create(n_background, 32, CV_8U);
  cv::RNG cvrng(seed);  // per-scene RNG: tests do not depend on their order
  if (n_person > 0) cvrng.fill(s.person_desc, cv::RNG::UNIFORM, 0, 256);
  if (n_background > 0) cvrng.fill(s.background_desc, cv::RNG::UNIFORM, 0, 256);
  return s;
}

// The frame with the person shifted by (dx, dy); keypoints of the person flagged dynamic.
features::FeatureFrame makeFrame(const Scene& s, float dx, float dy, bool with_person = true) {
  features::FeatureFrame f;
  f.width = 640;
  f.height = 480;
  std::vector<cv::Mat> rows;
  if (with_person) {
    for (size_t i = 0; i < s.person.size(); ++i) {
      f.keypoints.emplace_back(s.person[i] + cv::Point2f(dx, dy), 7.f);
      f.dynamic.push_back(1);
      rows.push_back(s.person_desc.row(static_cast<int>(i)));
    }
  }
  for (size_t i = 0; i < s.background.size(); ++i) {
    f.keypoints.emplace_back(s.background[i], 7.f);
    f.dynamic.push_back(0);
    rows.push_back(s.background_desc.row(static_cast<int>(i)));
  }
  cv::vconcat(rows, f.descriptors);
  f.keypoints_un = f.keypoints;
  f.depth.assign(f.keypoints.size(), 2.f);
  f.right_u.assign(f.keypoints.size(), -1.f);
  return f;
}

detection::Box personBox(const cv::Rect2f& r) {
  detection::Box b;
  b.class_id = 0;
  b.label = "person";
  b.score = 0.9f;
  b.rect = r;
  return b;
}

const cv::Rect2f kBox(200, 100, 120, 240);

// Frame 0 of `s` with the person detected in `box`: the tracker starts a track.
void startTrack(BoxTracker& tr, const Scene& s, const cv::Rect2f& box) {
  features::FeatureFrame f = makeFrame(s, 0, 0);
  tr.predict(f, {personBox(box)});
  tr.observe(f);
}

// Options whose near tracks outlive trackMaxAge by a margin the tests can see.
BoxTrackerOptions longNearOptions() {
  BoxTrackerOptions o;
  o.near_max_age = 12;
  EXPECT_LT(o.max_age, o.near_max_age);
  return o;
}

// Frames 1..n of `s` with the person moved by `step` a frame and no detection: each has the
// one carried box, which `check` inspects.
void expectCarriedNear(BoxTracker& tr, const Scene& s, int n, cv::Point2f step,
                       const std::function<void(const cv::Rect2f&, int)>& check) {
  for (int k = 1; k <= n; ++k) {
    features::FeatureFrame f = makeFrame(s, step.x * k, step.y * k);
    detection::Boxes b = tr.predict(f, {});
    ASSERT_EQ(b.size(), 1u) << "frame " << k;
    EXPECT_TRUE(b[0].tracked);
    check(b[0].rect, k);
    tr.observe(f);
  }
}

}  // namespace

TEST(BoxTracker, MissedDetectionGivesBoxMovedByKeypoints) {
  Scene s = makeScene(kBox, 40, 200, 1);
  BoxTracker tr(BoxTrackerOptions{});
  features::FeatureFrame f0 = makeFrame(s, 0, 0);
  detection::Boxes b0 = tr.predict(f0, {personBox(kBox)});
  ASSERT_EQ(b0.size(), 1u);
  EXPECT_FALSE(b0[0].tracked);
  tr.observe(f0);
  features::FeatureFrame f1 = makeFrame(s, 12, -7);
  detection::Boxes b1 = tr.predict(f1, {});
  ASSERT_EQ(b1.size(), 1u);
  EXPECT_TRUE(b1[0].tracked);
  EXPECT_EQ(b1[0].label, "person");
  EXPECT_NEAR(b1[0].rect.x, kBox.x + 12, 0.5);
  EXPECT_NEAR(b1[0].rect.y, kBox.y - 7, 0.5);
  EXPECT_NEAR(b1[0].rect.width, kBox.width, 1e-3);
  // Keeps following over further missed frames.
  tr.observe(f1);
  features::FeatureFrame f2 = makeFrame(s, 20, -10);
  detection::Boxes b2 = tr.predict(f2, {});
  ASSERT_EQ(b2.size(), 1u);
  EXPECT_NEAR(b2[0].rect.x, kBox.x + 20, 0.5);
  EXPECT_NEAR(b2[0].rect.y, kBox.y - 10, 0.5);
}

TEST(BoxTracker, BackgroundKeypointsNotScreenedDoNotDragTheBox) {
  // Static background keypoints inside the box (dynamic = 0) stay put; only the person moves.
  Scene s = makeScene(kBox, 30, 0, 2);
  Scene bg = makeScene(kBox, 30, 0, 3);  // "person" keypoints of bg used as static in-box texture
  BoxTracker tr(BoxTrackerOptions{});
  auto frame = [&](float dx) {
    features::FeatureFrame f = makeFrame(s, dx, 0);
    for (int i = 0; i < 30; ++i) {
      f.keypoints.emplace_back(bg.person[i], 7.f);
      f.dynamic.push_back(0);
    }
    cv::vconcat(f.descriptors, bg.person_desc, f.descriptors);
    return f;
  };
  features::FeatureFrame f0 = frame(0);
  tr.predict(f0, {personBox(kBox)});
  tr.observe(f0);
  detection::Boxes b1 = tr.predict(frame(15), {});
  ASSERT_EQ(b1.size(), 1u);
  EXPECT_NEAR(b1[0].rect.x, kBox.x + 15, 0.5);
}

TEST(BoxTracker, TrackDroppedAfterMaxAge) {
  Scene s = makeScene(kBox, 40, 100, 4);
  BoxTrackerOptions o;
  o.max_age = 3;
  BoxTracker tr(o);
  startTrack(tr, s, kBox);
  features::FeatureFrame f;
  for (int k = 1; k <= 3; ++k) {
    f = makeFrame(s, 2.f * k, 0);
    EXPECT_EQ(tr.predict(f, {}).size(), 1u) << "frame " << k;
    tr.observe(f);
  }
  f = makeFrame(s, 8, 0);
  EXPECT_TRUE(tr.predict(f, {}).empty());
  EXPECT_EQ(tr.numTracks(), 0u);
}

TEST(BoxTracker, DetectionRefreshesTrackWithoutDuplicate) {
  Scene s = makeScene(kBox, 40, 100, 5);
  BoxTrackerOptions o;
  o.max_age = 2;
  BoxTracker tr(o);
  startTrack(tr, s, kBox);
  features::FeatureFrame f;
  f = makeFrame(s, 5, 0);
  ASSERT_EQ(tr.predict(f, {}).size(), 1u);
  tr.observe(f);
  // Detected again (slightly different box): only the detection, one track.
  f = makeFrame(s, 10, 0);
  cv::Rect2f det(kBox.x + 8, kBox.y + 3, kBox.width - 4, kBox.height + 6);
  detection::Boxes b = tr.predict(f, {personBox(det)});
  ASSERT_EQ(b.size(), 1u);
  EXPECT_FALSE(b[0].tracked);
  EXPECT_EQ(b[0].rect, det);
  EXPECT_EQ(tr.numTracks(), 1u);
  tr.observe(f);
  // The age restarted: two more missed frames are carried (max_age 2), the third is not.
  for (int k = 1; k <= 2; ++k) {
    f = makeFrame(s, 10.f + k, 0);
    EXPECT_EQ(tr.predict(f, {}).size(), 1u) << "frame " << k;
    tr.observe(f);
  }
  EXPECT_TRUE(tr.predict(makeFrame(s, 13, 0), {}).empty());
}

TEST(BoxTracker, NoMatchDropsTrack) {
  Scene s = makeScene(kBox, 40, 100, 6);
  BoxTracker tr(BoxTrackerOptions{});
  startTrack(tr, s, kBox);
  features::FeatureFrame f;
  // The person is gone (only the background is seen).
  EXPECT_TRUE(tr.predict(makeFrame(s, 0, 0, false), {}).empty());
  EXPECT_EQ(tr.numTracks(), 0u);
  // Moved farther than the search radius: no match either.
  BoxTracker tr2(BoxTrackerOptions{});
  tr2.predict(f, {personBox(kBox)});
  tr2.observe(f);
  EXPECT_TRUE(tr2.predict(makeFrame(s, 100, 0), {}).empty());
}

TEST(BoxTracker, TwoPeopleOneDetectedOneTracked) {
  const cv::Rect2f a(50, 100, 100, 200), b(400, 120, 100, 200);
  Scene sa = makeScene(a, 30, 0, 7), sb = makeScene(b, 30, 100, 8);
  auto frame = [&](float dxa, float dxb) {
    features::FeatureFrame fa = makeFrame(sa, dxa, 0), fb = makeFrame(sb, dxb, 0);
    fa.keypoints.insert(fa.keypoints.end(), fb.keypoints.begin(), fb.keypoints.end());
    fa.dynamic.insert(fa.dynamic.end(), fb.dynamic.begin(), fb.dynamic.end());
    cv::vconcat(fa.descriptors, fb.descriptors, fa.descriptors);
    return fa;
  };
  BoxTracker tr(BoxTrackerOptions{});
  features::FeatureFrame f = frame(0, 0);
  EXPECT_EQ(tr.predict(f, {personBox(a), personBox(b)}).size(), 2u);
  tr.observe(f);
  f = frame(4, -9);
  cv::Rect2f a1(a.x + 4, a.y, a.width, a.height);
  detection::Boxes out = tr.predict(f, {personBox(a1)});
  ASSERT_EQ(out.size(), 2u);
  EXPECT_FALSE(out[0].tracked);
  EXPECT_TRUE(out[1].tracked);
  EXPECT_NEAR(out[1].rect.x, b.x - 9, 0.5);
  // Same input, fresh tracker: same output (deterministic).
  BoxTracker tr2(BoxTrackerOptions{});
  features::FeatureFrame g = frame(0, 0);
  tr2.predict(g, {personBox(a), personBox(b)});
  tr2.observe(g);
  detection::Boxes out2 = tr2.predict(frame(4, -9), {personBox(a1)});
  ASSERT_EQ(out2.size(), 2u);
  EXPECT_EQ(out2[1].rect, out[1].rect);
}

TEST(BoxTracker, BoxLeavingTheImageIsDropped) {
  const cv::Rect2f r(560, 100, 70, 200);
  Scene s = makeScene(r, 40, 50, 9);
  BoxTrackerOptions o;
  o.radius_px = 100;
  BoxTracker tr(o);
  startTrack(tr, s, r);
  features::FeatureFrame f;
  // Moved 70 px right: only 10 px of 70 remain inside the 640-px image (keypoints clipped).
  features::FeatureFrame g = makeFrame(s, 70, 0);
  EXPECT_TRUE(tr.predict(g, {}).empty());
}

TEST(BoxTracker, LowScoreDetectionNotCarried) {
  Scene s = makeScene(kBox, 40, 100, 10);
  BoxTracker tr(BoxTrackerOptions{});  // min_score 0.5
  features::FeatureFrame f = makeFrame(s, 0, 0);
  detection::Box weak = personBox(kBox);
  weak.score = 0.35f;
  tr.predict(f, {weak});
  tr.observe(f);
  EXPECT_TRUE(tr.predict(makeFrame(s, 5, 0), {}).empty());
  BoxTrackerOptions o;
  o.min_score = 0.3;
  BoxTracker tr2(o);
  tr2.predict(f, {weak});
  tr2.observe(f);
  EXPECT_EQ(tr2.predict(makeFrame(s, 5, 0), {}).size(), 1u);
}

// A person filling most of the view: the detector was sure of them, then scored them low, then
// finds nothing, and their keypoints no longer match (here: gone from the frame). The box is
// held where it was, for max_age frames. It is dropped at once with trackNearFraction 1, when
// it is small, and when the detector never scored it at least trackMinScore.
TEST(BoxTracker, NearPersonHeldWhileUnmatched) {
  const cv::Rect2f near_box(100, 20, 440, 450);  // 64 % of the image
  Scene s = makeScene(near_box, 60, 100, 12);
  detection::Box sure = personBox(near_box), weak = personBox(near_box);
  weak.score = 0.35f;
  auto start = [&](BoxTracker& tr, const detection::Boxes& first) {
    for (const detection::Boxes& d : {first, detection::Boxes{weak}}) {
      features::FeatureFrame f = makeFrame(s, 0, 0);
      tr.predict(f, d);
      tr.observe(f);
    }
  };
  BoxTrackerOptions o;
  ASSERT_LE(o.near_fraction, 0.6);
  BoxTracker tr(o);
  start(tr, {sure});
  for (int k = 1; k <= o.max_age; ++k) {
    features::FeatureFrame f = makeFrame(s, 0, 0, false);
    detection::Boxes b = tr.predict(f, {});
    ASSERT_EQ(b.size(), 1u) << "frame " << k;
    EXPECT_TRUE(b[0].tracked);
    EXPECT_EQ(b[0].rect, near_box);
    tr.observe(f);
  }
  EXPECT_TRUE(tr.predict(makeFrame(s, 0, 0, false), {}).empty());

  BoxTracker never_sure(o);
  start(never_sure, {weak});
  EXPECT_TRUE(never_sure.predict(makeFrame(s, 0, 0, false), {}).empty());
  o.near_fraction = 1.0;
  BoxTracker off(o);
  start(off, {sure});
  EXPECT_TRUE(off.predict(makeFrame(s, 0, 0, false), {}).empty());
  // A small box, sure then weak: dropped as before.
  Scene small = makeScene(kBox, 40, 100, 13);
  detection::Box weak_small = personBox(kBox);
  weak_small.score = 0.35f;
  BoxTracker tr_small(BoxTrackerOptions{});
  for (const detection::Box& d : {personBox(kBox), weak_small}) {
    features::FeatureFrame f = makeFrame(small, 0, 0);
    tr_small.predict(f, {d});
    tr_small.observe(f);
  }
  EXPECT_TRUE(tr_small.predict(makeFrame(small, 0, 0, false), {}).empty());
}

// A person filling the view whom the detector has lost while their keypoints still match: the
// box follows them for trackNearMaxAge frames; once the matches are gone it is held for
// trackMaxAge frames more at most, as any near track.
TEST(BoxTracker, NearPersonFollowedWhileMatched) {
  const cv::Rect2f near_box(100, 20, 440, 450);
  const Scene s = makeScene(near_box, 60, 100, 14);
  const BoxTrackerOptions o = longNearOptions();
  BoxTracker tr(o);
  startTrack(tr, s, near_box);
  const float step = 2.f;
  expectCarriedNear(tr, s, o.near_max_age, cv::Point2f(step, 0.f), [&](const cv::Rect2f& r, int frame) {
    EXPECT_NEAR(r.x, near_box.x + step * frame, 0.5) << "frame " << frame;
  });
  int k = o.near_max_age + 1;
  EXPECT_TRUE(tr.predict(makeFrame(s, step * k, 0), {}).empty());

  // Matched for a few frames, then unmatched: held trackMaxAge frames, then dropped.
  BoxTracker held(o);
  startTrack(held, s, near_box);
  const int matched = 4;
  for (k = 1; k <= matched; ++k) {
    features::FeatureFrame f = makeFrame(s, step * k, 0);
    ASSERT_EQ(held.predict(f, {}).size(), 1u);
    held.observe(f);
  }
  for (int u = 1; u <= o.max_age; ++u) {
    features::FeatureFrame f = makeFrame(s, 0, 0, false);
    detection::Boxes b = held.predict(f, {});
    ASSERT_EQ(b.size(), 1u) << "unmatched frame " << u;
    EXPECT_NEAR(b[0].rect.x, near_box.x + step * matched, 0.5);
    held.observe(f);
  }
  EXPECT_TRUE(held.predict(makeFrame(s, 0, 0, false), {}).empty());

  // A box that is not near the camera keeps trackMaxAge, matched or not.
  BoxTracker small(o);
  const Scene s_small = makeScene(kBox, 40, 100, 15);
  startTrack(small, s_small, kBox);
  for (k = 1; k <= o.max_age; ++k) {
    features::FeatureFrame f = makeFrame(s_small, step * k, 0);
    ASSERT_EQ(small.predict(f, {}).size(), 1u);
    small.observe(f);
  }
  EXPECT_TRUE(small.predict(makeFrame(s_small, step * k, 0), {}).empty());
}

// A person filling the view, cut by the top of the image, whose keypoints move up: the carried
// box is clipped a little more every frame and soon covers less than nine tenths of the
// image's height, but the track stays a near person's for trackNearMaxAge frames.
TEST(BoxTracker, NearPersonStaysNearWhileTheBorderClipsTheirBox) {
  const cv::Rect2f near_box(100, 0, 440, 460);
  const Scene s = makeScene(near_box, 80, 100, 15);
  const BoxTrackerOptions o = longNearOptions();
  BoxTracker tr(o);
  startTrack(tr, s, near_box);
  const float step = -3.f;
  expectCarriedNear(tr, s, o.near_max_age, cv::Point2f(0.f, step), [&](const cv::Rect2f& r, int frame) {
    EXPECT_NEAR(r.height, near_box.height + step * frame, 0.5) << "frame " << frame;
  });
  ASSERT_LT(near_box.height + step * o.near_max_age, 0.9f * 480);  // no longer near by its box
}

TEST(BoxTracker, NearPersonBoxIsLargeAndTall) {
  EXPECT_TRUE(screening::isNearPersonBox(cv::Rect2f(100, 20, 440, 450), 640, 480, 0.4));
  // Wide over a rolled view but short: not a person at the lens.
  EXPECT_FALSE(screening::isNearPersonBox(cv::Rect2f(10, 10, 600, 350), 640, 480, 0.4));
  EXPECT_FALSE(screening::isNearPersonBox(cv::Rect2f(200, 0, 120, 480), 640, 480, 0.4));  // small
  // trackNearFraction 1 turns the rule off, even for a box over the whole image.
  EXPECT_FALSE(screening::isNearPersonBox(cv::Rect2f(0, 0, 640, 480), 640, 480, 1.0));
  EXPECT_FALSE(screening::isNearPersonBox(cv::Rect2f(0, 0, 640, 480), 0, 0, 0.4));  // no image size
}

// Asynchronous detection: a detection of the image two frames back arrives while the person
// walks 6 px a frame. It is moved by the person's keypoint travel since that image.
TEST(BoxTracker, StaleDetectionMovedByTheTravelSinceItsImage) {
  const double dt = 1.0 / 30;
  const float step = 6.f;
  for (const bool shift : {true, false}) {
    Scene s = makeScene(kBox, 40, 100, 12);
    BoxTrackerOptions o;
    o.shift_stale = shift;
    BoxTracker tr(o);
    for (int k = 0; k < 3; ++k) {
      features::FeatureFrame f = makeFrame(s, k * step, 0);
      f.stamp = k * dt;
      tr.predict(f, k == 0 ? detection::Boxes{personBox(kBox)} : detection::Boxes{}, k == 0);
      tr.observe(f);
    }
    features::FeatureFrame f3 = makeFrame(s, 3 * step, 0);
    f3.stamp = 3 * dt;
    detection::Box stale = personBox(cv::Rect2f(kBox.x + step, kBox.y, kBox.width - 10, kBox.height));
    stale.age_s = 2 * dt;  // the image of frame 1
    const detection::Boxes out = tr.predict(f3, {stale});
    ASSERT_EQ(out.size(), 1u) << "shift " << shift;
    EXPECT_FALSE(out[0].tracked);
    EXPECT_NEAR(out[0].rect.x, kBox.x + (shift ? 3 : 1) * step, 0.5) << "shift " << shift;
    EXPECT_NEAR(out[0].rect.width, kBox.width - 10, 1e-3);
    EXPECT_EQ(tr.numTracks(), 1u);
  }
}

TEST(BoxTracker, StaleDetectionOlderThanTheTrackStaysWhereItWasSeen) {
  Scene s = makeScene(kBox, 40, 100, 13);
  BoxTracker tr(BoxTrackerOptions{});
  features::FeatureFrame f0 = makeFrame(s, 0, 0);
  f0.stamp = 10.0;
  tr.predict(f0, {personBox(kBox)});
  tr.observe(f0);
  features::FeatureFrame f1 = makeFrame(s, 6, 0);
  f1.stamp = 10.0 + 1.0 / 30;
  detection::Box stale = personBox(kBox);
  stale.age_s = 0.5;  // before the track began: its travel is not known
  const detection::Boxes out = tr.predict(f1, {stale});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].rect, kBox);
}

TEST(BoxTracker, OptionsValidated) {
  BoxTrackerOptions o;
  o.max_age = 0;
  EXPECT_THROW(BoxTracker{o}, Error);
  o = BoxTrackerOptions{};
  o.radius_px = -1;
  EXPECT_THROW(BoxTracker{o}, Error);
  o = BoxTrackerOptions{};
  o.near_fraction = 1.5;
  EXPECT_THROW(BoxTracker{o}, Error);
  o = BoxTrackerOptions{};
  o.near_max_age = 0;
  EXPECT_THROW(BoxTracker{o}, Error);
  // Every key's value: test/slam/test_options.cpp.
  Config bad = Config::fromString("%YAML:1.0\nScreening.trackMaxAge: 0\n", "bad.yaml");
  try {
    screening::ScreeningOptions::load(bad);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("trackMaxAge"), std::string::npos) << e.what();
  }
}
