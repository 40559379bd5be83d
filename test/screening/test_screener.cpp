// Algorithm 1 on constructed depth sets, the adaptive k of Eq. 8, determinism and modes.
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/screening/screener.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <random>
#include <utility>

using namespace yolo_slam;
using namespace yolo_slam::screening;

namespace {

// A person (depth ~1.5 m, +-0.15 m body relief) standing in front of a wall at 4 m, inside a
// box x in [100, 300): the person covers x in [150, 250). Outside the box: more wall.
struct Scene {
  features::FeatureFrame frame;
  std::vector<bool> person;
  detection::Boxes boxes;
};

Scene makeScene(unsigned seed = 1, int n_person = 120, int n_wall_in_box = 60, int n_out = 100) {
  Scene s;
  s.frame.width = 640;
  s.frame.height = 480;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  auto add = [&](float x, float y, float d, bool person) {
    s.frame.keypoints.emplace_back(cv::Point2f(x, y), 31.f);
    s.frame.depth.push_back(d);
    s.person.push_back(person);
  };
  for (int i = 0; i < n_person; ++i) add(150 + 100 * u(rng), 60 + 400 * u(rng), 1.35f + 0.3f * u(rng), true);
  for (int i = 0; i < n_wall_in_box; ++i) {
    float x = u(rng) < 0.5f ? 100 + 48 * u(rng) : 252 + 48 * u(rng);
    add(x, 60 + 400 * u(rng), 3.9f + 0.2f * u(rng), false);
  }
  for (int i = 0; i < n_out; ++i) add(350 + 280 * u(rng), 480 * u(rng), 3.9f + 0.2f * u(rng), false);
  s.frame.keypoints_un = s.frame.keypoints;
  detection::Box b;
  b.label = "person";
  b.score = 0.9f;
  b.rect = cv::Rect2f(100, 50, 200, 420);
  s.boxes.push_back(b);
  return s;
}

// A 100x100 frame with keypoints on the row y = 50 at `xs`, screened as `dynamic` says.
features::FeatureFrame rowFrame(std::initializer_list<float> xs, std::vector<uint8_t> dynamic) {
  features::FeatureFrame f;
  f.width = 100;
  f.height = 100;
  for (float x : xs) f.keypoints.emplace_back(cv::Point2f(x, 50), 31.f);
  f.dynamic = std::move(dynamic);
  return f;
}

detection::Boxes oneBox(const cv::Rect2f& r) {
  detection::Boxes boxes(1);
  boxes[0].rect = r;
  return boxes;
}

}  // namespace

TEST(AdaptiveIterations, MatchesEquation8) {
  // k = log(1 - P) / log(1 - w^2)
  EXPECT_NEAR(adaptiveIterations(0.5, 0.99, 2), std::log(0.01) / std::log(0.75), 1e-12);
  EXPECT_NEAR(adaptiveIterations(0.5, 0.99, 2), 16.0078, 1e-3);
  EXPECT_NEAR(adaptiveIterations(0.9, 0.99, 2), 2.7730, 1e-3);
  EXPECT_TRUE(std::isinf(adaptiveIterations(0.0, 0.99, 2)));
  EXPECT_EQ(adaptiveIterations(1.0, 0.99, 2), 0.0);
  // More inliers, fewer iterations.
  EXPECT_GT(adaptiveIterations(0.3, 0.99, 2), adaptiveIterations(0.6, 0.99, 2));
}

TEST(DepthRansac, PersonPlaneInFrontOfWallIsTheConsensus) {
  for (ScreeningVariant v : {ScreeningVariant::Paper, ScreeningVariant::Grow}) {
    ScreeningOptions o;
    o.variant = v;
    o.variance_threshold_m2 = 0.05;
    Screener scr(o);
    Scene s = makeScene();
    ScreeningStats st = scr.screen(s.frame, s.boxes);
    int person_dropped = 0, wall_box_kept = 0, wall_box = 0, outside_dropped = 0;
    for (size_t i = 0; i < s.frame.size(); ++i) {
      const bool in_box = s.boxes[0].rect.contains(s.frame.keypoints[i].pt);
      if (s.person[i]) person_dropped += s.frame.dynamic[i];
      else if (in_box) { ++wall_box; wall_box_kept += !s.frame.dynamic[i]; }
      else outside_dropped += s.frame.dynamic[i];
    }
    EXPECT_EQ(person_dropped, 120) << toString(v);
    EXPECT_EQ(wall_box_kept, wall_box) << toString(v);
    EXPECT_EQ(outside_dropped, 0) << toString(v);
    EXPECT_EQ(st.in_boxes, 180);
    EXPECT_EQ(st.dropped, 120);
    EXPECT_EQ(st.kept, 60);
    EXPECT_GT(st.iterations, 0);
    // w = 120/180: k = log(0.01)/log(1 - 0.444) = 7.8, so RANSAC stops long before the cap.
    EXPECT_LT(st.iterations, 50);
  }
}

TEST(DepthRansac, DeterministicGivenSeed) {
  ScreeningOptions o;
  o.variance_threshold_m2 = 0.01;  // tight: several candidate clusters, so sampling matters
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(1.f, 4.f);
  std::vector<float> d(300);
  for (float& x : d) x = u(rng);
  Screener scr(o);
  ConsensusResult a = scr.depthRansac(d, 42), b = scr.depthRansac(d, 42);
  EXPECT_EQ(a.members, b.members);
  EXPECT_EQ(a.iterations, b.iterations);
  Scene s1 = makeScene(), s2 = makeScene();
  scr.screen(s1.frame, s1.boxes);
  scr.screen(s2.frame, s2.boxes);
  EXPECT_EQ(s1.frame.dynamic, s2.frame.dynamic);
}

TEST(DepthRansac, IterationsCappedAndSmallSets) {
  ScreeningOptions o;
  o.variance_threshold_m2 = 1e-9;  // nothing agrees: w stays 0, k stays infinite
  o.max_iterations = 37;
  Screener scr(o);
  std::vector<float> d;
  for (int i = 0; i < 50; ++i) d.push_back(1.0f + 0.1f * i);
  EXPECT_EQ(scr.depthRansac(d, 0).iterations, 37);
  EXPECT_TRUE(scr.depthRansac({}, 0).members.empty());
  EXPECT_EQ(scr.depthRansac({2.0f}, 0).members, std::vector<int>{0});
  ScreeningOptions o2;
  o2.variance_threshold_m2 = 0.05;
  o2.variant = ScreeningVariant::Paper;
  EXPECT_EQ(Screener(o2).depthRansac({2.0f, 2.1f}, 0).members, (std::vector<int>{0, 1}));
}

TEST(Modes, BehaveAsSpecified) {
  auto run = [](DynamicMode m, Scene& s) {
    ScreeningOptions o;
    o.mode = m;
    o.variance_threshold_m2 = 0.05;
    return Screener(o).screen(s.frame, s.boxes);
  };
  Scene off = makeScene();
  ScreeningStats st = run(DynamicMode::Off, off);
  EXPECT_EQ(off.frame.countDynamic(), 0u);
  EXPECT_EQ(st.dropped, 0);

  Scene det = makeScene();
  st = run(DynamicMode::Detect, det);
  EXPECT_EQ(det.frame.countDynamic(), 180u);  // everything in the box
  EXPECT_EQ(st.in_boxes, 180);
  EXPECT_EQ(st.kept, 0);

  // Geometry: the whole image is one box; the dominant depth cluster is the wall (160 of 280
  // keypoints), which G drops: the paper's reason why G alone is worse than D + G.
  Scene geo = makeScene();
  ScreeningOptions po;
  po.mode = DynamicMode::Geometry;
  po.variant = ScreeningVariant::Paper;
  po.variance_threshold_m2 = 0.05;
  st = Screener(po).screen(geo.frame, geo.boxes);
  EXPECT_EQ(st.in_boxes, 280);
  EXPECT_EQ(geo.frame.countDynamic(), 160u);
  for (size_t i = 0; i < geo.frame.size(); ++i) EXPECT_EQ(geo.frame.dynamic[i], geo.person[i] ? 0 : 1);
  // The nearest variant (default) takes the nearer cluster, the person, even without boxes.
  Scene geo_near = makeScene();
  st = run(DynamicMode::Geometry, geo_near);
  EXPECT_EQ(st.in_boxes, 280);
  for (size_t i = 0; i < geo_near.frame.size(); ++i)
    EXPECT_EQ(geo_near.frame.dynamic[i], geo_near.person[i] ? 1 : 0);

  Scene dg = makeScene();
  run(DynamicMode::DetectGeometry, dg);
  EXPECT_EQ(dg.frame.countDynamic(), 120u);

  // No boxes: detect and detect+geometry drop nothing.
  Scene none = makeScene();
  none.boxes.clear();
  EXPECT_EQ(run(DynamicMode::DetectGeometry, none).dropped, 0);
  EXPECT_EQ(none.frame.countDynamic(), 0u);
}

TEST(Screener, NoDepthRuleAndExistingLabels) {
  Scene s = makeScene();
  s.frame.depth[0] = 0;                   // a person keypoint without depth
  s.frame.depth[130] = 0;                 // a wall keypoint in the box without depth
  s.frame.dynamic.assign(s.frame.size(), 0);
  s.frame.dynamic[250] = 1;               // propagated label outside any box survives
  ScreeningOptions o;
  o.variance_threshold_m2 = 0.05;
  o.no_depth = ScreeningOptions::NoDepthRule::Dynamic;
  Screener(o).screen(s.frame, s.boxes);
  EXPECT_EQ(s.frame.dynamic[0], 1);
  EXPECT_EQ(s.frame.dynamic[130], 1);
  EXPECT_EQ(s.frame.dynamic[250], 1);
  Scene t = makeScene();
  t.frame.depth[0] = 0;
  o.no_depth = ScreeningOptions::NoDepthRule::Static;
  Screener(o).screen(t.frame, t.boxes);
  EXPECT_EQ(t.frame.dynamic[0], 0);
  EXPECT_EQ(t.frame.dynamic[1], 1);
}

TEST(Options, ParseAndLoad) {
  EXPECT_EQ(parseDynamicMode("off"), DynamicMode::Off);
  EXPECT_EQ(parseDynamicMode("detect"), DynamicMode::Detect);
  EXPECT_EQ(parseDynamicMode("geometry"), DynamicMode::Geometry);
  EXPECT_EQ(parseDynamicMode("detect+geometry"), DynamicMode::DetectGeometry);
  for (auto m : {DynamicMode::Off, DynamicMode::Detect, DynamicMode::Geometry, DynamicMode::DetectGeometry})
    EXPECT_EQ(parseDynamicMode(toString(m)), m);
  EXPECT_THROW(parseDynamicMode("D+G"), Error);

  Config c = Config::fromString(
      "Screening.mode: \"detect\"\nScreening.variant: \"paper\"\nScreening.varianceThreshold: 0.2\n"
      "Screening.probability: 0.95\nScreening.maxIterations: 77\nScreening.seed: 5\n"
      "Screening.noDepth: \"static\"\nScreening.boxDilation: 0.1\n", "s.yaml");
  ScreeningOptions o = ScreeningOptions::load(c);
  EXPECT_EQ(o.mode, DynamicMode::Detect);
  EXPECT_EQ(o.variant, ScreeningVariant::Paper);
  EXPECT_DOUBLE_EQ(o.variance_threshold_m2, 0.2);
  EXPECT_DOUBLE_EQ(o.probability, 0.95);
  EXPECT_EQ(o.max_iterations, 77);
  EXPECT_EQ(o.seed, 5u);
  EXPECT_EQ(o.no_depth, ScreeningOptions::NoDepthRule::Static);
  EXPECT_DOUBLE_EQ(o.box_dilation, 0.1);

  ScreeningOptions d = ScreeningOptions::load(Config());
  EXPECT_EQ(d.mode, DynamicMode::DetectGeometry);

  for (const char* bad : {"Screening.mode: \"fast\"\n", "Screening.varianceThreshold: -1\n",
                          "Screening.probability: 1.5\n", "Screening.noDepth: \"maybe\"\n",
                          "Screening.maxIterations: 0\n"}) {
    try {
      ScreeningOptions::load(Config::fromString(bad, "bad.yaml"));
      FAIL() << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
    }
  }
}

TEST(Metrics, CountsAgainstMask) {
  Scene s = makeScene();
  ScreeningOptions o;
  o.variance_threshold_m2 = 0.05;
  Screener(o).screen(s.frame, s.boxes);
  cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(150, 0, 101, 480)).setTo(255);  // person x in [150, 250]
  ScreeningMetrics m = evaluateScreening(s.frame, mask, s.boxes);
  EXPECT_EQ(m.dynamic_total, 120);
  EXPECT_EQ(m.dynamic_dropped, 120);
  EXPECT_EQ(m.static_in_boxes, 60);
  EXPECT_EQ(m.static_in_boxes_kept, 60);
  EXPECT_EQ(m.static_total, 160);
  EXPECT_DOUBLE_EQ(m.dynamicRecall(), 1.0);
  EXPECT_DOUBLE_EQ(m.staticRetention(), 1.0);
  // Detect mode keeps nothing in the box.
  Scene d = makeScene();
  o.mode = DynamicMode::Detect;
  Screener(o).screen(d.frame, d.boxes);
  ScreeningMetrics md = evaluateScreening(d.frame, mask, d.boxes);
  EXPECT_DOUBLE_EQ(md.staticRetention(), 0.0);
  md += m;
  EXPECT_EQ(md.dynamic_total, 240);
  EXPECT_DOUBLE_EQ(Json(m)["dynamic_recall"].get<double>(), 1.0);
  EXPECT_THROW(evaluateScreening(s.frame, cv::Mat(10, 10, CV_8UC1), s.boxes), Error);
  EXPECT_THROW(loadMask("/nonexistent/mask.png"), Error);
}

TEST(DepthRansac, GrowFollowsAPersonDeeperThanOneWindow) {
  // A tilted camera sees a standing person's feet deeper than the head: depth 1.5 m at the top
  // to 2.3 m at the bottom, a 10 x 20 grid of keypoints; a wall at 4 m fills the box sides.
  features::FeatureFrame f;
  f.width = 640;
  f.height = 480;
  std::vector<bool> person;
  for (int r = 0; r < 20; ++r) {
    for (int c = 0; c < 10; ++c) {
      const float y = 60 + 20 * r;
      f.keypoints.emplace_back(cv::Point2f(155 + 10 * c, y), 31.f);
      f.depth.push_back(1.5f + 0.8f * (y - 60) / 380);
      person.push_back(true);
    }
  }
  for (int i = 0; i < 60; ++i) {
    f.keypoints.emplace_back(cv::Point2f(i % 2 ? 110 : 270, 60 + 6 * i), 31.f);
    f.depth.push_back(4.0f);
    person.push_back(false);
  }
  detection::Boxes boxes(1);
  boxes[0].rect = cv::Rect2f(100, 50, 200, 420);
  ScreeningOptions o;  // 0.02 m^2: a window of +-0.3 m around a tight pair
  o.variant = ScreeningVariant::Paper;
  features::FeatureFrame paper = f;
  Screener(o).screen(paper, boxes);
  o.variant = ScreeningVariant::Grow;
  features::FeatureFrame grown = f;
  Screener(o).screen(grown, boxes);
  int paper_person = 0, grow_person = 0, grow_wall = 0;
  for (size_t i = 0; i < f.size(); ++i) {
    if (person[i]) {
      paper_person += paper.dynamic[i];
      grow_person += grown.dynamic[i];
    } else {
      grow_wall += grown.dynamic[i];
    }
  }
  EXPECT_LT(paper_person, 180);  // the window covers only part of the 0.8 m span
  EXPECT_EQ(grow_person, 200);
  EXPECT_EQ(grow_wall, 0);
}

TEST(Screener, NearestNoDepthRuleCopiesTheNeighbour) {
  Scene s = makeScene();
  // A depth-less keypoint right next to a person keypoint, one next to a wall keypoint.
  s.frame.keypoints.emplace_back(s.frame.keypoints[0].pt + cv::Point2f(1, 1), 31.f);
  s.frame.depth.push_back(0.f);
  s.frame.keypoints.emplace_back(s.frame.keypoints[130].pt + cv::Point2f(1, 1), 31.f);
  s.frame.depth.push_back(0.f);
  ScreeningOptions o;
  o.no_depth = ScreeningOptions::NoDepthRule::Nearest;
  Screener(o).screen(s.frame, s.boxes);
  const size_t n = s.frame.size();
  EXPECT_EQ(s.frame.dynamic[n - 2], 1);
  EXPECT_EQ(s.frame.dynamic[n - 1], 0);
}

TEST(Metrics, IgnoredBorderBand) {
  cv::Mat mask(100, 100, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(40, 0, 20, 100)).setTo(255);
  const features::FeatureFrame f = rowFrame({50.f, 41.f, 58.f, 37.f, 10.f}, {1, 0, 0, 1, 0});
  const detection::Boxes boxes = oneBox(cv::Rect2f(0, 0, 100, 100));
  ScreeningMetrics all = evaluateScreening(f, mask, boxes);
  EXPECT_EQ(all.dynamic_total, 3);
  EXPECT_EQ(all.dynamic_dropped, 1);
  EXPECT_EQ(all.static_in_boxes, 2);
  EXPECT_EQ(all.static_in_boxes_kept, 1);
  // With a 5 px band, x = 41, 58 (inside, near the edge) and 37 (outside, near) are left out.
  ScreeningMetrics core = evaluateScreening(f, mask, boxes, 5);
  EXPECT_EQ(core.dynamic_total, 1);
  EXPECT_EQ(core.dynamic_dropped, 1);
  EXPECT_EQ(core.static_in_boxes, 1);
  EXPECT_EQ(core.static_in_boxes_kept, 1);
}

TEST(Metrics, DynamicKeypointsOutsideEveryBoxAreCountedApart) {
  cv::Mat mask(100, 100, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(40, 0, 40, 100)).setTo(255);  // a person from x = 40 to 79
  // On the mask: 45 and 50 inside the box (one dropped), 70 and 75 outside it (one dropped).
  const features::FeatureFrame f = rowFrame({45.f, 50.f, 70.f, 75.f, 10.f}, {1, 0, 1, 0, 0});
  const detection::Boxes boxes = oneBox(cv::Rect2f(40, 0, 20, 100));  // clips the person's right half
  ScreeningMetrics m = evaluateScreening(f, mask, boxes);
  EXPECT_EQ(m.dynamic_total, 4);
  EXPECT_EQ(m.dynamic_dropped, 2);
  EXPECT_EQ(m.dynamic_outside_boxes, 2);
  EXPECT_EQ(m.dynamic_outside_dropped, 1);
  EXPECT_DOUBLE_EQ(m.dynamicRecall(), 0.5);
  EXPECT_DOUBLE_EQ(m.dynamicRecallInBoxes(), 0.5);
  ScreeningMetrics sum = m;
  sum += m;
  EXPECT_EQ(sum.dynamic_outside_boxes, 4);
  EXPECT_EQ(Json(m)["dynamic_outside_boxes"], 2) << Json(m).dump();
}

TEST(Metrics, StaticKeypointsOnAPersonsOutlineAreCountedApart) {
  cv::Mat mask(100, 100, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(40, 0, 20, 100)).setTo(255);  // a person from x = 40 to 59
  // Static (off the mask): 37 and 62 are 3 px from it (their FAST circle reaches the person),
  // 30 is 10 px away at level 0 but 3 px at a level of scale 3.6, 10 and 90 are far. Dropped:
  // 37, 30 and 10.
  features::FeatureFrame f = rowFrame({37.f, 62.f, 30.f, 10.f, 90.f}, {1, 0, 1, 1, 0});
  f.keypoints[2].size = 31.f * 3.6f;
  const ScreeningMetrics m = evaluateScreening(f, mask, oneBox(cv::Rect2f(0, 0, 100, 100)));
  EXPECT_EQ(m.static_total, 5);
  EXPECT_EQ(m.static_dropped, 3);
  EXPECT_EQ(m.static_on_outline, 3);
  EXPECT_EQ(m.static_on_outline_dropped, 2);
  EXPECT_DOUBLE_EQ(m.staticDropRate(), 0.6);
  EXPECT_DOUBLE_EQ(m.staticDropRateOffOutline(), 0.5);  // 10 dropped, 90 kept
  ScreeningMetrics sum = m;
  sum += m;
  EXPECT_EQ(sum.static_on_outline_dropped, 4);
  const Json j(m);
  EXPECT_EQ(j["static_on_outline"], 3) << j.dump();
  EXPECT_DOUBLE_EQ(j["static_drop_rate_off_outline"].get<double>(), 0.5);
}

// The outline test reads a disc around each keypoint; its definition is the Euclidean distance
// to the nearest dynamic pixel, which cv::distanceTransform gives for the whole mask.
TEST(Metrics, OutlineTestAgreesWithTheDistanceTransform) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  cv::Mat mask(60, 80, CV_8UC1, cv::Scalar(0));
  for (int i = 0; i < 6; ++i)  // scattered blobs and single pixels, some on the border
    mask.at<uint8_t>(int(u(rng) * 60), int(u(rng) * 80)) = 255;
  mask(cv::Rect(30, 20, 7, 5)).setTo(200);
  mask(cv::Rect(0, 50, 4, 10)).setTo(255);
  cv::Mat to_dynamic;
  cv::distanceTransform(mask <= 127, to_dynamic, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  features::FeatureFrame f;
  f.width = mask.cols;
  f.height = mask.rows;
  int expected = 0;
  for (int i = 0; i < 3000; ++i) {
    const int x = int(u(rng) * mask.cols), y = int(u(rng) * mask.rows);
    if (mask.at<uint8_t>(y, x) > 127) continue;
    const float size = 31.f * std::pow(1.2f, float(i % 8));
    f.keypoints.emplace_back(cv::Point2f(float(x), float(y)), size);
    const double r = features::OrbExtractor::kFastRadius * features::OrbExtractor::levelScale(f.keypoints.back());
    expected += to_dynamic.at<float>(y, x) <= r ? 1 : 0;
  }
  f.dynamic.assign(f.keypoints.size(), 0);
  const ScreeningMetrics m = evaluateScreening(f, mask, {});
  EXPECT_EQ(m.static_total, static_cast<int>(f.keypoints.size()));
  EXPECT_GT(expected, 100);
  EXPECT_EQ(m.static_on_outline, expected);
}

TEST(NearestVariant, PersonIsTheNearestClusterWhenTheBackgroundDominatesTheBox) {
  // A sitting person (60 keypoints, 1.8-2.0 m) in a box filled mostly by a desk/wall at 3.5 m
  // (150 keypoints): Algorithm 1's "largest set" is the background, the nearest sizeable
  // cluster is the person.
  Scene s = makeScene(2, 60, 150, 50);
  for (size_t i = 0; i < s.frame.size(); ++i)
    s.frame.depth[i] = s.person[i] ? 1.8f + 0.2f * (i % 7) / 6.f : 3.4f + 0.2f * (i % 5) / 4.f;
  auto count = [&](const Scene& t, bool person) {
    int dropped = 0;
    for (size_t i = 0; i < t.frame.size(); ++i)
      if (t.person[i] == person && t.boxes[0].rect.contains(t.frame.keypoints[i].pt))
        dropped += t.frame.dynamic[i];
    return dropped;
  };
  ScreeningOptions o;
  o.box_dilation = 0;
  o.variant = ScreeningVariant::Paper;
  Scene p = s;
  Screener(o).screen(p.frame, p.boxes);
  EXPECT_EQ(count(p, true), 0);      // the paper's rule drops the background ...
  EXPECT_EQ(count(p, false), 150);   // ... and keeps the person
  o.variant = ScreeningVariant::Nearest;
  Scene q = s;
  Screener(o).screen(q.frame, q.boxes);
  EXPECT_EQ(count(q, true), 60);
  EXPECT_EQ(count(q, false), 0);
  // A handful of near outliers (below cluster_min_fraction of the largest window) is not
  // taken for the person.
  std::vector<float> d(q.frame.depth.begin(), q.frame.depth.begin() + 210);
  d.push_back(0.8f);
  d.push_back(0.82f);
  std::vector<int> m = Screener(o).nearestCluster(d);
  EXPECT_EQ(m.size(), 60u);
  for (int i : m) EXPECT_LT(i, 60);
  EXPECT_TRUE(Screener(o).nearestCluster({}).empty());
}

TEST(Screener, NearDynamicRuleAndDepthOnlyDilation) {
  Scene s = makeScene();
  s.frame.dynamic.assign(s.frame.size(), 0);
  // Depth-less keypoints: on the person (5 px from a person keypoint), in the wall part of the
  // box far from the person, and in the dilation ring right of the box.
  const cv::Point2f on_person = s.frame.keypoints[0].pt + cv::Point2f(5, 0);
  s.frame.keypoints.emplace_back(on_person, 31.f);
  s.frame.keypoints.emplace_back(cv::Point2f(102, 250), 31.f);
  s.frame.keypoints.emplace_back(cv::Point2f(304, 250), 31.f);
  for (int k = 0; k < 3; ++k) s.frame.depth.push_back(0.f);
  const size_t n = s.frame.size();
  ScreeningOptions o;
  o.variance_threshold_m2 = 0.05;
  o.variant = ScreeningVariant::Nearest;
  o.no_depth = ScreeningOptions::NoDepthRule::NearDynamic;
  o.no_depth_radius_px = 20;
  o.box_dilation = 0.05;  // box x in [90, 310)
  Scene a = s;
  Screener(o).screen(a.frame, a.boxes);
  EXPECT_EQ(a.frame.dynamic[n - 3], 1);  // next to the person
  EXPECT_EQ(a.frame.dynamic[n - 2], 0);  // wall region: the person starts 48 px away
  EXPECT_EQ(a.frame.dynamic[n - 1], 0);
  o.no_depth = ScreeningOptions::NoDepthRule::Dynamic;
  Scene b = s;
  Screener(o).screen(b.frame, b.boxes);
  EXPECT_EQ(b.frame.dynamic[n - 2], 1);
  EXPECT_EQ(b.frame.dynamic[n - 1], 1);  // the dilation ring drops depth-less keypoints too
  o.dilation_depth_only = true;
  Scene c = s;
  Screener(o).screen(c.frame, c.boxes);
  EXPECT_EQ(c.frame.dynamic[n - 2], 1);  // inside the detected box: the rule applies
  EXPECT_EQ(c.frame.dynamic[n - 1], 0);  // ring: only depth can make it dynamic
  EXPECT_EQ(c.frame.dynamic[n - 3], 1);

  Config cfg = Config::fromString(
      "Screening.variant: \"nearest\"\nScreening.noDepth: \"near-dynamic\"\n"
      "Screening.noDepthRadius: 12\nScreening.clusterMinFraction: 0.4\n"
      "Screening.dilationDepthOnly: true\n", "s.yaml");
  ScreeningOptions l = ScreeningOptions::load(cfg);
  EXPECT_EQ(l.variant, ScreeningVariant::Nearest);
  EXPECT_EQ(l.no_depth, ScreeningOptions::NoDepthRule::NearDynamic);
  EXPECT_DOUBLE_EQ(l.no_depth_radius_px, 12);
  EXPECT_DOUBLE_EQ(l.cluster_min_fraction, 0.4);
  EXPECT_TRUE(l.dilation_depth_only);
  EXPECT_THROW(ScreeningOptions::load(Config::fromString("Screening.clusterMinFraction: 0\n", "b.yaml")), Error);
}

TEST(Metrics, PersonRecallLeavesOtherMovingObjectsOut) {
  cv::Mat mask(100, 100, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(40, 0, 20, 100)).setTo(255);  // a person
  mask(cv::Rect(60, 40, 20, 20)).setTo(200);  // the box they carry (yolo_slam_synth's value)
  // Person: 45 dropped, 50 dropped; box: 65 kept, 75 kept; wall: 10.
  const features::FeatureFrame f = rowFrame({45.f, 50.f, 65.f, 75.f, 10.f}, {1, 1, 0, 0, 0});
  const detection::Boxes boxes = oneBox(cv::Rect2f(38, 0, 44, 100));
  ScreeningMetrics m = evaluateScreening(f, mask, boxes);
  EXPECT_EQ(m.dynamic_total, 4);
  EXPECT_EQ(m.person_total, 2);
  EXPECT_EQ(m.person_dropped, 2);
  EXPECT_DOUBLE_EQ(m.dynamicRecall(), 0.5);
  EXPECT_DOUBLE_EQ(m.personRecall(), 1.0);
  EXPECT_EQ(m.static_total, 1);
  ScreeningMetrics sum = m;
  sum += m;
  EXPECT_EQ(sum.person_total, 4);
  EXPECT_DOUBLE_EQ(Json(m)["person_recall"].get<double>(), 1.0) << Json(m).dump();
}

TEST(Screener, SilhouetteRuleDropsKeypointsOnThePersonsOutline) {
  // Depth image of makeScene's layout: wall at 4 m, the person (x 150-249) at 1.5 m, and a
  // 3 px band without depth on the person's right outline (x 250-252), as a Kinect loses it.
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(4.f));
  depth(cv::Rect(150, 0, 100, 480)).setTo(1.5f);
  depth(cv::Rect(250, 0, 3, 480)).setTo(0.f);
  auto scene = [] {
    Scene s = makeScene();
    auto add = [&](cv::Point2f p, float d, float size) {
      s.frame.keypoints.emplace_back(p, size);
      s.frame.depth.push_back(d);
      s.person.push_back(false);
    };
    add({251, 200}, 0.f, 31.f);       // in the hole band: no depth of its own
    add({251, 300}, 4.f, 31.f);       // on the outline, its depth pixel read the wall
    add({253, 400}, 4.f, 31.f * 1.2f * 1.2f * 1.2f * 1.2f);  // level 4: radius 2 x 2.07 = 4 px
    add({253, 100}, 4.f, 31.f);       // same place at level 0: 2 px reach only the hole band
    add({120, 200}, 4.f, 31.f);       // wall inside the box, far from the person
    s.frame.keypoints_un = s.frame.keypoints;
    return s;
  };
  ScreeningOptions o;
  o.no_depth = ScreeningOptions::NoDepthRule::Static;  // the no-depth rule must not interfere
  ASSERT_EQ(o.silhouette_radius_px, 2.0);
  Scene s = scene();
  const size_t n = s.frame.size();
  ScreeningStats st = Screener(o).screen(s.frame, s.boxes, depth);
  EXPECT_EQ(s.frame.dynamic[n - 5], 1);
  EXPECT_EQ(s.frame.dynamic[n - 4], 1);
  EXPECT_EQ(s.frame.dynamic[n - 3], 1);
  EXPECT_EQ(s.frame.dynamic[n - 2], 0);
  EXPECT_EQ(s.frame.dynamic[n - 1], 0);
  EXPECT_EQ(st.silhouette, 3);

  // Without the depth image, or with the radius 0, the rule is off.
  Scene s2 = scene();
  EXPECT_EQ(Screener(o).screen(s2.frame, s2.boxes).silhouette, 0);
  EXPECT_EQ(s2.frame.dynamic[n - 4], 0);
  o.silhouette_radius_px = 0;
  Scene s3 = scene();
  EXPECT_EQ(Screener(o).screen(s3.frame, s3.boxes, depth).silhouette, 0);
  EXPECT_EQ(s3.frame.dynamic[n - 4], 0);

  // A depth image of another size is an error naming the rule.
  o.silhouette_radius_px = 2;
  Scene s4 = scene();
  EXPECT_THROW(Screener(o).screen(s4.frame, s4.boxes, cv::Mat(240, 320, CV_32F, cv::Scalar(1.f))), Error);
  EXPECT_THROW(ScreeningOptions::load(Config::fromString("Screening.silhouetteRadius: -1\n", "s.yaml")), Error);
  EXPECT_EQ(ScreeningOptions::load(Config::fromString("Screening.silhouetteRadius: 5\n", "s.yaml")).silhouette_radius_px, 5.0);
}

TEST(Screener, DepthProbeKeepsHolesOfTheBackground) {
  // makeScene's layout over a depth image: wall at 4 m, the person (x 150-249) at 1.5 m, a
  // 1 px hole on the person's right outline (x 250), the projector's shadow left of the
  // person (x 140-149) and a large hole (x 100-149, y 60-99) with nothing valid near its middle.
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(4.f));
  depth(cv::Rect(150, 0, 100, 480)).setTo(1.5f);
  depth(cv::Rect(250, 0, 1, 480)).setTo(0.f);
  depth(cv::Rect(140, 0, 10, 480)).setTo(0.f);
  depth(cv::Rect(100, 60, 50, 40)).setTo(0.f);
  auto scene = [] {
    Scene s = makeScene();
    for (cv::Point2f p : {cv::Point2f(250, 200), cv::Point2f(142, 300), cv::Point2f(144, 80)}) {
      s.frame.keypoints.emplace_back(p, 31.f);
      s.frame.depth.push_back(0.f);
    }
    s.frame.keypoints_un = s.frame.keypoints;
    return s;
  };
  ScreeningOptions o;
  o.silhouette_radius_px = 0;  // the silhouette rule would take the outline keypoint itself
  ASSERT_EQ(o.no_depth_probe_radius_px, 0.0);
  Scene s = scene();
  const size_t n = s.frame.size();
  Screener(o).screen(s.frame, s.boxes, depth);
  // Without the probe near-dynamic drops all three (each is near the person).
  EXPECT_EQ(s.frame.dynamic[n - 3], 1);
  EXPECT_EQ(s.frame.dynamic[n - 2], 1);
  EXPECT_EQ(s.frame.dynamic[n - 1], 1);

  o.no_depth_probe_radius_px = 4;
  Scene s2 = scene();
  Screener(o).screen(s2.frame, s2.boxes, depth);
  EXPECT_EQ(s2.frame.dynamic[n - 3], 1);  // the person's depth 1 px away: the outline
  EXPECT_EQ(s2.frame.dynamic[n - 2], 0);  // the wall 3 px away, the person 8: the shadow
  EXPECT_EQ(s2.frame.dynamic[n - 1], 1);  // nothing within 4 px: near-dynamic decides

  // Without the depth image the probe is off.
  Scene s3 = scene();
  Screener(o).screen(s3.frame, s3.boxes);
  EXPECT_EQ(s3.frame.dynamic[n - 2], 1);
  EXPECT_THROW(ScreeningOptions::load(Config::fromString("Screening.noDepthProbeRadius: -1\n", "s.yaml")), Error);
  EXPECT_EQ(ScreeningOptions::load(Config::fromString("Screening.noDepthProbeRadius: 6\n", "s.yaml")).no_depth_probe_radius_px, 6.0);
}

namespace {

// Keypoints with depth scattered over rectangles, each labelled with whose it is (0: the wall).
struct Crowd {
  features::FeatureFrame f;
  std::vector<int> who;
  std::mt19937 rng;
  std::uniform_real_distribution<float> u{0.f, 1.f};

  explicit Crowd(unsigned seed) : rng(seed) {
    f.width = 640;
    f.height = 480;
  }
  float uniform() { return u(rng); }
  void add(float x, float y, float d, int id) {
    f.keypoints.emplace_back(cv::Point2f(x, y), 31.f);
    f.depth.push_back(d);
    who.push_back(id);
  }
  // n keypoints uniform in x0 + [0, w), y0 + [0, h), depth d0 + [0, dd).
  void scatter(int n, float x0, float w, float y0, float h, float d0, float dd, int id) {
    for (int i = 0; i < n; ++i) add(x0 + w * uniform(), y0 + h * uniform(), d0 + dd * uniform(), id);
  }
  // Screens a copy of the frame; the dropped keypoints per label.
  std::vector<int> dropped(const ScreeningOptions& o, const detection::Boxes& boxes, ScreeningStats* st = nullptr) const {
    features::FeatureFrame g = f;
    g.keypoints_un = g.keypoints;
    const ScreeningStats s = Screener(o).screen(g, boxes);
    if (st) *st = s;
    std::vector<int> n(*std::max_element(who.begin(), who.end()) + 1, 0);
    for (size_t i = 0; i < g.size(); ++i) n[who[i]] += g.dynamic[i];
    return n;
  }
};

detection::Boxes boxesAt(std::initializer_list<cv::Rect2f> rects) {
  detection::Boxes boxes;
  for (const cv::Rect2f& r : rects) {
    detection::Box b;
    b.rect = r;
    b.score = 0.9f;
    boxes.push_back(b);
  }
  return boxes;
}

}  // namespace

TEST(OcclusionRule, FindsThePersonBehindAnotherOne) {
  // Person A at 1.5 m, x in [300, 400); person B at 2.5 m behind and to the left, x in
  // [200, 340): A covers B's right part. The wall at 4 m. B's box holds A's left part,
  // which is B's box's nearest sizeable cluster, so without the rule B is never found.
  Crowd c(5);
  c.scatter(120, 300, 100, 60, 400, 1.4f, 0.2f, 1);
  c.scatter(50, 200, 100, 80, 380, 2.4f, 0.2f, 2);
  for (int i = 0; i < 120; ++i) {
    const float x = c.uniform() < 0.5f ? 100 + 95 * c.uniform() : 405 + 200 * c.uniform();
    c.add(x, 480 * c.uniform(), 3.9f + 0.2f * c.uniform(), 0);
  }
  // A, then B overlapping A's left part.
  const detection::Boxes boxes = boxesAt({cv::Rect2f(295, 50, 110, 420), cv::Rect2f(195, 70, 200, 400)});
  auto droppedOf = [&](bool rule) {
    ScreeningOptions o;
    o.occlusion_rule = rule;
    o.box_dilation = 0;
    ScreeningStats st;
    const std::vector<int> d = c.dropped(o, boxes, &st);
    EXPECT_EQ(st.occluded_boxes, rule ? 1 : 0);
    return d;
  };
  const std::vector<int> off = droppedOf(false), on = droppedOf(true);
  EXPECT_EQ(off[1], 120);
  EXPECT_LT(off[2], 10);  // B kept: its box found A
  EXPECT_EQ(on[1], 120);
  EXPECT_GE(on[2], 45);   // B found behind A
  EXPECT_LE(on[0], off[0] + 2);  // and not the wall
}

TEST(OcclusionRule, KeepsTwoPeopleSideBySideAtOneDepth) {
  // A and B walk side by side at 2 m; B's box holds more of A than of B, so B's set is mostly
  // A's. Screened again without A, B's box would find the arm of C (1.2 m) reaching into it and
  // leave B static: a nearer set than the one removed is no person behind, the first set stays.
  Crowd c(11);
  c.scatter(160, 200, 130, 60, 400, 1.95f, 0.1f, 1);
  c.scatter(40, 332, 66, 60, 400, 2.0f, 0.1f, 2);
  c.scatter(100, 400, 160, 40, 430, 1.15f, 0.1f, 3);
  c.scatter(60, 20, 160, 0, 480, 3.9f, 0.2f, 0);
  // A; B, holding A's right half and C's arm; C.
  const detection::Boxes boxes =
      boxesAt({cv::Rect2f(195, 50, 140, 420), cv::Rect2f(260, 50, 180, 420), cv::Rect2f(395, 30, 170, 445)});
  ScreeningOptions o;
  o.box_dilation = 0;
  const std::vector<int> dropped = c.dropped(o, boxes);
  EXPECT_EQ(dropped[1], 160);
  EXPECT_GE(dropped[2], 38);  // B, at A's depth, found with A
  EXPECT_EQ(dropped[3], 100);
  EXPECT_EQ(dropped[0], 0);
}

TEST(OcclusionRule, LeavesADuplicateDetectionAlone) {
  // Two boxes around one person (two models, or a carried box next to a detection) overlap by
  // far more than occlusionMaxIou: the second is not screened again, the wall stays.
  Scene s = makeScene(3);
  detection::Box dup = s.boxes[0];
  dup.rect = cv::Rect2f(105, 55, 190, 410);
  s.boxes.push_back(dup);
  ScreeningOptions o;
  const ScreeningStats st = Screener(o).screen(s.frame, s.boxes);
  EXPECT_EQ(st.occluded_boxes, 0);
  int wall_dropped = 0;
  for (size_t i = 0; i < s.frame.size(); ++i) wall_dropped += !s.person[i] && s.frame.dynamic[i];
  EXPECT_LE(wall_dropped, 6);
}
