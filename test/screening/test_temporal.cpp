// Frame-to-frame evidence (screening/temporal.h) on constructed RGB-D frames: a textured wall
// 3 m away, a person 1.5 m away, a camera that moves between frames; keypoints are the exact
// projections of the 3D points, descriptors fixed per point.
#include "yolo_slam/screening/temporal.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/screening/screener.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include <random>

using namespace yolo_slam;
using screening::TemporalOptions;
using screening::TemporalScreening;
using screening::TemporalStats;

namespace {

struct Point {
  cv::Vec3d X;  // world coordinates (camera 0 = world)
  cv::Mat desc;
  bool person = false;
};

struct World {
  std::vector<Point> points;
};

// Wall points spread over the view at 3 m (to 3 + 2 wall_relief); person points in a 0.5 x 1.2 m
// patch at 1.5 m centred at (person_x, 0).
World makeWorld(int n_wall, int n_person, double person_x, unsigned seed, double wall_relief = 0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  cv::RNG cvrng(seed);
  World w;
  auto add = [&](const cv::Vec3d& X, bool person) {
    Point p;
    p.X = X;
    p.person = person;
    p.desc.create(1, 32, CV_8U);
    cvrng.fill(p.desc, cv::RNG::UNIFORM, 0, 256);
    w.points.push_back(p);
  };
  for (int i = 0; i < n_wall; ++i) add({1.6 * u(rng), 1.2 * u(rng), 3.0 + wall_relief * (1 + u(rng))}, false);
  for (int i = 0; i < n_person; ++i) add({person_x + 0.25 * u(rng), 0.6 * u(rng), 1.5}, true);
  return w;
}

CameraModel camera() { return CameraModel(); }  // TUM fr3 intrinsics, 640 x 480

// The frame seen by a camera at (cam_x, 0, 0) looking down +z, with the person shifted by
// person_dx metres; `person_dynamic` flags the person's keypoints dynamic (screened), and
// `wall_dynamic_box` flags wall keypoints inside that image box (a false detection's drop).
features::FeatureFrame render(const World& w, double cam_x, double person_dx, bool person_dynamic,
                              const cv::Rect2f& wall_dynamic_box = cv::Rect2f()) {
  const CameraModel cam = camera();
  features::FeatureFrame f;
  f.width = cam.width;
  f.height = cam.height;
  std::vector<cv::Mat> rows;
  for (const auto& p : w.points) {
    const cv::Vec3d Xc = p.X + cv::Vec3d(p.person ? person_dx : 0.0, 0, 0) - cv::Vec3d(cam_x, 0, 0);
    const float u = static_cast<float>(cam.fx * Xc[0] / Xc[2] + cam.cx);
    const float v = static_cast<float>(cam.fy * Xc[1] / Xc[2] + cam.cy);
    if (!cam.inImage(u, v)) continue;
    f.keypoints.emplace_back(cv::Point2f(u, v), 31.f);  // level 0: size = patch diameter
    f.depth.push_back(static_cast<float>(Xc[2]));
    const bool dyn = p.person ? person_dynamic : wall_dynamic_box.contains(cv::Point2f(u, v));
    f.dynamic.push_back(dyn ? 1 : 0);
    rows.push_back(p.desc);
  }
  cv::vconcat(rows, f.descriptors);
  f.keypoints_un = f.keypoints;
  f.right_u.assign(f.keypoints.size(), -1.f);
  return f;
}

int countDynamic(const features::FeatureFrame& f, const World& w, bool person) {
  // Keypoints are in world-point order when every point is in the image (true of every scene
  // and camera position here).
  EXPECT_EQ(f.size(), w.points.size());
  int n = 0;
  for (size_t i = 0; i < f.size(); ++i) n += (f.dynamic[i] && w.points[i].person == person) ? 1 : 0;
  return n;
}

// The boxes of these scenes are the regions screened, as they are.
constexpr double kBoxDilation = 0;

TemporalOptions propagation() {
  TemporalOptions o;
  o.propagate_labels = true;
  o.static_box_veto = false;
  o.motion_screening = false;
  return o;
}

detection::Box box(const cv::Rect2f& r, float score) {
  detection::Box b;
  b.label = "person";
  b.score = score;
  b.rect = r;
  return b;
}

}  // namespace

TEST(Temporal, StaticSceneIsStaticConsistentUnderCameraMotion) {
  const World w = makeWorld(200, 0, 0, 1);
  TemporalScreening ts(propagation(), kBoxDilation);
  features::FeatureFrame f0 = render(w, 0.0, 0, false);
  ASSERT_EQ(f0.size(), w.points.size());
  ts.apply(f0, {}, camera());
  features::FeatureFrame f1 = render(w, 0.03, 0, false);  // 3 cm sideways: ~5 px of parallax
  const TemporalStats st = ts.apply(f1, {}, camera());
  EXPECT_TRUE(st.motionOk());
  EXPECT_EQ(st.matched, 200);
  EXPECT_EQ(st.static_consistent, 200);
  EXPECT_EQ(st.propagated, 0);
  // The per-keypoint verdict travels with the frame (tracking reads it).
  ASSERT_EQ(f1.motion.size(), f1.size());
  EXPECT_EQ(std::count(f1.motion.begin(), f1.motion.end(), int8_t{1}), 200);
  ASSERT_EQ(f0.motion.size(), f0.size());  // first frame: nothing to compare with
  EXPECT_EQ(std::count(f0.motion.begin(), f0.motion.end(), int8_t{-1}), 200);
}

TEST(Temporal, LabelsOfAMovingPersonPropagateWhereTheDetectorMissedThem) {
  const World w = makeWorld(200, 60, 0.3, 2);
  TemporalScreening ts(propagation(), kBoxDilation);
  features::FeatureFrame f0 = render(w, 0.0, 0.0, true);
  ASSERT_EQ(f0.size(), w.points.size());
  ts.apply(f0, {}, camera());
  // Frame 1: no detection (person not screened); the person walked 5 cm (~18 px at 1.5 m).
  features::FeatureFrame f1 = render(w, 0.01, 0.05, false);
  ASSERT_EQ(f1.size(), w.points.size());
  const TemporalStats st = ts.apply(f1, {}, camera());
  ASSERT_TRUE(st.motionOk());
  EXPECT_EQ(st.propagated, 60);
  EXPECT_EQ(countDynamic(f1, w, true), 60);
  EXPECT_EQ(countDynamic(f1, w, false), 0);
}

TEST(Temporal, WronglyDroppedBackgroundDoesNotPropagate) {
  const World w = makeWorld(300, 0, 0, 3);
  TemporalScreening ts(propagation(), kBoxDilation);
  // A false detection dropped the wall keypoints in this box in frame 0 only.
  features::FeatureFrame f0 = render(w, 0.0, 0, false, cv::Rect2f(100, 100, 200, 200));
  const int dropped0 = static_cast<int>(f0.countDynamic());
  ASSERT_GT(dropped0, 20);
  ts.apply(f0, {}, camera());
  features::FeatureFrame f1 = render(w, 0.02, 0, false);
  const TemporalStats st = ts.apply(f1, {}, camera());
  ASSERT_TRUE(st.motionOk());
  EXPECT_EQ(st.propagated, 0);
  EXPECT_EQ(f1.countDynamic(), 0u);
}

TEST(Temporal, LabelsStopAfterMaxAgeFramesWithoutScreening) {
  const World w = makeWorld(200, 60, 0.2, 4);
  TemporalOptions o = propagation();
  o.propagate_max_age = 2;
  TemporalScreening ts(o, kBoxDilation);
  features::FeatureFrame f = render(w, 0.0, 0.0, true);
  ts.apply(f, {}, camera());
  std::vector<int> marked;
  for (int k = 1; k <= 4; ++k) {
    f = render(w, 0.01 * k, 0.04 * k, false);  // person keeps walking, never detected again
    marked.push_back(ts.apply(f, {}, camera()).propagated);
  }
  EXPECT_EQ(marked[0], 60);
  EXPECT_EQ(marked[1], 60);
  EXPECT_EQ(marked[2], 0);
  EXPECT_EQ(marked[3], 0);
}

// Two frames: a walking person (dropped), and a false detection on the wall top left whose
// wall keypoints were dropped too.
struct VetoScene {
  World w = makeWorld(300, 60, 0.3, 5);
  cv::Rect2f picture{60, 60, 150, 150};
  features::FeatureFrame f1;
  cv::Rect2f person;
};

VetoScene vetoScene(TemporalScreening& ts) {
  VetoScene v;
  features::FeatureFrame f0 = render(v.w, 0.0, 0.0, true, v.picture);
  ts.apply(f0, {}, camera());
  v.f1 = render(v.w, 0.02, 0.05, true, v.picture);
  std::vector<cv::Point2f> pts;
  for (size_t i = 0; i < v.f1.size(); ++i)
    if (v.w.points[i].person) pts.push_back(v.f1.keypoints[i].pt);
  const cv::Rect r = cv::boundingRect(pts);
  v.person = cv::Rect2f(r.x - 2.f, r.y - 2.f, r.width + 4.f, r.height + 4.f);
  return v;
}

TemporalOptions vetoOnly() {
  TemporalOptions o;
  o.static_box_veto = true;
  o.motion_screening = false;
  return o;
}

TEST(Temporal, StaticBoxVetoKeepsAnUnsureFalseDetectionButNotAWalkingPerson) {
  TemporalScreening ts(vetoOnly(), kBoxDilation);
  VetoScene v = vetoScene(ts);
  features::FeatureFrame& f1 = v.f1;
  const World& w = v.w;
  const cv::Rect2f picture = v.picture, person = v.person;
  const int wall_dropped = countDynamic(f1, w, false);
  ASSERT_GE(wall_dropped, 10);
  ASSERT_TRUE((person & picture).empty());
  // Scores below staticBoxMaxScore (0.8): both boxes may be vetoed, only the picture is.
  const TemporalStats st = ts.apply(f1, {box(picture, 0.5f), box(person, 0.6f)}, camera());
  ASSERT_TRUE(st.motionOk());
  EXPECT_EQ(st.boxes_vetoed, 1);
  EXPECT_EQ(st.vetoed, wall_dropped);
  EXPECT_EQ(countDynamic(f1, w, false), 0);   // the picture's keypoints are kept
  EXPECT_EQ(countDynamic(f1, w, true), 60);   // the walking person stays dropped
}

TEST(Temporal, AVetoedBoxKeepsWhatWasDroppedWithinItsReach) {
  // The false detection's drops reach past its box, as screening beyond the boxes grows them:
  // with the reach, the vetoed box keeps them all; without, those past the box stay dropped.
  const cv::Rect2f inner(75, 75, 120, 120);  // the picture (60, 60, 150, 150) less 15 px a side
  for (double reach : {0.0, 0.25}) {
    TemporalScreening ts(vetoOnly(), kBoxDilation, reach);
    VetoScene v = vetoScene(ts);
    int past = 0;
    for (size_t i = 0; i < v.f1.size(); ++i)
      past += (v.f1.dynamic[i] && !v.w.points[i].person && !screening::inside(inner, v.f1.keypoints[i].pt)) ? 1 : 0;
    ASSERT_GE(past, 3);
    const TemporalStats st = ts.apply(v.f1, {box(inner, 0.5f), box(v.person, 0.6f)}, camera());
    ASSERT_EQ(st.boxes_vetoed, 1) << "reach " << reach;
    EXPECT_EQ(countDynamic(v.f1, v.w, false), reach > 0 ? 0 : past) << "reach " << reach;
    EXPECT_EQ(countDynamic(v.f1, v.w, true), 60);
  }
}

TEST(Temporal, StaticBoxVetoNeverOverrulesAConfidentDetection) {
  // A seated person is as still as a picture; the detector is sure of people, not of pictures.
  TemporalScreening ts(vetoOnly(), kBoxDilation);
  VetoScene v = vetoScene(ts);
  const int wall_dropped = countDynamic(v.f1, v.w, false);
  const TemporalStats st = ts.apply(v.f1, {box(v.picture, 0.95f), box(v.person, 0.95f)}, camera());
  ASSERT_TRUE(st.motionOk());
  EXPECT_EQ(st.boxes_vetoed, 0);
  EXPECT_EQ(countDynamic(v.f1, v.w, false), wall_dropped);
}

TemporalOptions motionOnly() {
  TemporalOptions o;
  o.static_box_veto = false;
  o.motion_screening = true;
  return o;
}

TEST(Temporal, MotionScreeningDropsAnUndetectedWalkerButNotTheMovingCamerasStaticScene) {
  // A room with depth: two fronto-parallel layers moving sideways are explained by one camera
  // motion (a turn plus a larger shift), so a flat wall would hide the walker's motion.
  const World w = makeWorld(400, 60, 0.3, 11, 1.5);
  TemporalScreening ts(motionOnly(), kBoxDilation);
  features::FeatureFrame f0 = render(w, 0.0, 0.0, false);
  ASSERT_EQ(f0.size(), w.points.size());
  ts.apply(f0, {}, camera());
  // No box in either frame; the camera moved 2 cm and the person 5 cm (~18 px at 1.5 m).
  features::FeatureFrame f1 = render(w, 0.02, 0.05, false);
  ASSERT_EQ(f1.size(), w.points.size());
  const TemporalStats st = ts.apply(f1, {}, camera());
  ASSERT_TRUE(st.motionOk());
  // Most: a walker's keypoint with fewer than motionMinSupport neighbours within
  // motionSupportRadius stays (this walker's 60 points are sparse: about 4 in that radius).
  EXPECT_GE(countDynamic(f1, w, true), 40);
  EXPECT_EQ(st.motion_dropped, countDynamic(f1, w, true));
  EXPECT_EQ(countDynamic(f1, w, false), 0);
}

TEST(Temporal, MotionScreeningNeedsMovedNeighboursThatMoveAlike) {
  // Three isolated points of the wall "move" (a false match would look like this): each has no
  // moved neighbour, so none is dropped; nor are slow movers below motionMinResidual.
  World w = makeWorld(200, 0, 0, 12);
  TemporalScreening ts(motionOnly(), kBoxDilation);
  features::FeatureFrame f0 = render(w, 0.0, 0.0, false);
  ts.apply(f0, {}, camera());
  features::FeatureFrame f1 = render(w, 0.02, 0.0, false);
  const float shifts[3][2] = {{15, 0}, {0, -14}, {-12, 9}};
  const cv::Point2f at[3] = {{100, 100}, {320, 240}, {540, 380}};
  for (int k = 0; k < 3; ++k) {
    // The keypoint nearest to `at` jumps by `shift`.
    size_t best = 0;
    for (size_t i = 1; i < f1.size(); ++i)
      if (cv::norm(f1.keypoints[i].pt - at[k]) < cv::norm(f1.keypoints[best].pt - at[k])) best = i;
    f1.keypoints[best].pt += cv::Point2f(shifts[k][0], shifts[k][1]);
    f1.keypoints_un[best].pt = f1.keypoints[best].pt;
  }
  const TemporalStats st = ts.apply(f1, {}, camera());
  ASSERT_TRUE(st.motionOk());
  EXPECT_EQ(st.matched, 200);
  EXPECT_EQ(st.motion_dropped, 0);
  EXPECT_EQ(f1.countDynamic(), 0u);

  // A person creeping 1 cm per frame (~3.6 px at 1.5 m) is below the residual bound.
  const World slow = makeWorld(400, 60, 0.3, 13, 1.5);
  TemporalScreening ts2(motionOnly(), kBoxDilation);
  features::FeatureFrame g0 = render(slow, 0.0, 0.0, false);
  ts2.apply(g0, {}, camera());
  features::FeatureFrame g1 = render(slow, 0.0, 0.01, false);
  EXPECT_EQ(ts2.apply(g1, {}, camera()).motion_dropped, 0);
}

TEST(Temporal, MotionScreeningKeepsAKeypointWithAStaticTwin) {
  // Repeated texture on a still patch (the "person" points, not moving here): in the previous
  // frame every patch point has a twin 16 px to its right whose descriptor matches better than
  // its own (a few bits differ). The nearest-descriptor match picks the twin, so the patch seems
  // to move coherently by 16 px; the point's own, slightly worse lookalike at its static
  // position tells it is static.
  const World w = makeWorld(400, 60, 0.3, 14, 1.5);
  TemporalScreening ts(motionOnly(), kBoxDilation);
  features::FeatureFrame f0 = render(w, 0.0, 0.0, false);
  features::FeatureFrame f1 = render(w, 0.0, 0.0, false);
  ASSERT_EQ(f0.size(), w.points.size());
  cv::Mat twins;
  for (size_t i = 0; i < w.points.size(); ++i) {
    if (!w.points[i].person) continue;
    cv::KeyPoint twin = f0.keypoints[i];
    twin.pt.x += 16;
    f0.keypoints.push_back(twin);
    f0.keypoints_un.push_back(twin);
    f0.depth.push_back(f0.depth[i]);
    f0.right_u.push_back(-1.f);
    f0.dynamic.push_back(0);
    twins.push_back(f0.descriptors.row(static_cast<int>(i)).clone());
    f0.descriptors.at<uint8_t>(static_cast<int>(i), 0) ^= 0x0F;  // 4 bits off: still a lookalike
  }
  cv::vconcat(f0.descriptors, twins, f0.descriptors);
  ts.apply(f0, {}, camera());
  const TemporalStats st = ts.apply(f1, {}, camera());
  ASSERT_TRUE(st.motionOk());
  EXPECT_EQ(st.matched, 460);
  EXPECT_LE(st.static_consistent, 400);  // the patch matched its twins: "moved"
  EXPECT_EQ(st.motion_dropped, 0);
  EXPECT_EQ(f1.countDynamic(), 0u);
}

TEST(Temporal, NothingChangesWithoutACameraMotionEstimate) {
  // Too few static keypoints with depth: the motion is unknown, so no label can be judged.
  const World w = makeWorld(8, 60, 0.0, 6);
  TemporalScreening ts(propagation(), kBoxDilation);
  features::FeatureFrame f0 = render(w, 0.0, 0.0, true);
  ts.apply(f0, {}, camera());
  features::FeatureFrame f1 = render(w, 0.01, 0.05, false);
  const TemporalStats st = ts.apply(f1, {}, camera());
  EXPECT_FALSE(st.motionOk());
  EXPECT_EQ(st.propagated, 0);
  EXPECT_EQ(f1.countDynamic(), 0u);
}

TEST(Temporal, ClearForgetsThePreviousFrame) {
  const World w = makeWorld(200, 60, 0.3, 7);
  TemporalScreening ts(propagation(), kBoxDilation);
  features::FeatureFrame f0 = render(w, 0.0, 0.0, true);
  ts.apply(f0, {}, camera());
  ts.clear();
  features::FeatureFrame f1 = render(w, 0.01, 0.05, false);
  const TemporalStats st = ts.apply(f1, {}, camera());
  EXPECT_EQ(st.matched, 0);
  EXPECT_EQ(f1.countDynamic(), 0u);
}

TEST(Temporal, OptionsComeFromScreeningKeysAndBadValuesNameTheKey) {
  const Config cfg = Config::fromString(
      "%YAML:1.0\nScreening.propagateLabels: 1\nScreening.propagateMaxAge: 5\n"
      "Screening.staticBoxVeto: 0\nScreening.staticBoxFraction: 0.7\n"
      "Screening.temporalStaticTolerance: 4\nScreening.motionScreening: 1\nScreening.motionMinSupport: 5\n");
  const TemporalOptions o = screening::ScreeningOptions::load(cfg).temporal;
  EXPECT_TRUE(o.propagate_labels);
  EXPECT_EQ(o.propagate_max_age, 5);
  EXPECT_FALSE(o.static_box_veto);
  EXPECT_DOUBLE_EQ(o.static_box_fraction, 0.7);
  EXPECT_DOUBLE_EQ(o.static_tolerance_px, 4.0);
  EXPECT_TRUE(o.motion_screening);
  EXPECT_EQ(o.motion_min_support, 5);
  try {
    screening::ScreeningOptions::load(
        Config::fromString("%YAML:1.0\nScreening.staticBoxFraction: 1.5\n"));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("staticBoxFraction"), std::string::npos) << e.what();
  }
  TemporalOptions bad;
  bad.propagate_max_age = 0;
  EXPECT_THROW((TemporalScreening{bad, kBoxDilation}), Error);
}
