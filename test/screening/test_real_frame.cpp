// Screening on the real TUM fr3_walking_xyz frame 1341846313.592026 (shared data): two people
// (one standing at ~1.3 m on the right, one sitting at ~2 m on the left) and the published
// person mask. Regions below were annotated by hand by looking at the image.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/screening/screener.h"

#include <gtest/gtest.h>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>

using namespace yolo_slam;
using namespace yolo_slam::screening;

namespace {

struct Real {
  features::FeatureFrame frame;
  cv::Mat mask;
  cv::Mat depth_m;  // metres, for the silhouette rule
  detection::Boxes boxes;
};

const Real& real() {
  static const Real r = [] {
    Real r;
    const std::string dir = joinPath(sharedDir(), "data/tum/rgbd_dataset_freiburg3_walking_xyz");
    cv::Mat bgr = cv::imread(joinPath(dir, "rgb/1341846313.592026.png"), cv::IMREAD_COLOR);
    cv::Mat raw = cv::imread(joinPath(dir, "depth/1341846313.592088.png"), cv::IMREAD_ANYDEPTH);
    r.mask = loadMask(joinPath(dir, "dynamic_mask/1341846313.592026.png"));
    if (bgr.empty() || raw.empty()) return r;
    raw.convertTo(r.depth_m, CV_32F, 1.0 / 5000.0);
    CameraModel cam;
    cam.rgb_order = false;
    features::OrbExtractor orb{features::OrbOptions{}};
    r.frame = features::buildFeatureFrame(orb, cam, bgr, r.depth_m, 0.0);
    // Boxes around the two people: bounding boxes of the mask's two connected components.
    detection::Box b;
    b.label = "person";
    b.rect = cv::Rect2f(473, 0, 167, 480);
    r.boxes.push_back(b);
    b.rect = cv::Rect2f(35, 111, 210, 369);
    r.boxes.push_back(b);
    return r;
  }();
  return r;
}

// Keypoints with valid depth inside `region`: how many, how many marked dynamic.
std::pair<int, int> countIn(const features::FeatureFrame& f, const cv::Rect& region) {
  int n = 0, dyn = 0;
  for (size_t i = 0; i < f.size(); ++i) {
    if (f.depth[i] <= 0 || !region.contains(cv::Point(f.keypoints[i].pt))) continue;
    ++n;
    dyn += f.dynamic[i];
  }
  return {n, dyn};
}

// Hand-annotated regions (pixels of the 640x480 image).
const cv::Rect kRightShirt(510, 80, 110, 250);  // standing person's checked shirt
const cv::Rect kLeftTorso(60, 195, 65, 115);    // sitting person's black T-shirt
const cv::Rect kMonitor(185, 195, 55, 65);      // monitor inside the left box, ~3 m
const cv::Rect kPartition(155, 125, 30, 65);    // partition/poster behind the sitting head
const cv::Rect kWallTop(40, 115, 40, 60);       // far wall in the left box's top-left corner

}  // namespace

TEST(RealFrame, DefaultDropsPeopleAndKeepsDeskAndWall) {
  const Real& r = real();
  ASSERT_GT(r.frame.size(), 500u) << "shared TUM frame missing? check YOLO_SLAM_SHARED";
  features::FeatureFrame f = r.frame;
  ScreeningOptions o;  // defaults: detect+geometry, nearest variant, noDepth near-dynamic
  ScreeningStats st = Screener(o).screen(f, r.boxes);
  EXPECT_GT(st.in_boxes, 500);

  for (const cv::Rect& person : {kRightShirt, kLeftTorso}) {
    auto c = countIn(f, person);
    EXPECT_GE(c.first, 10);
    EXPECT_EQ(c.second, c.first) << "person region " << person;
  }
  for (const cv::Rect& still : {kMonitor, kPartition, kWallTop}) {
    auto c = countIn(f, still);
    EXPECT_GE(c.first, 8);
    EXPECT_EQ(c.second, 0) << "static region " << still;
  }

  // Against the whole mask (defaults: recall 0.908, retention 0.862 with the mask as published;
  // 0.953 / 0.972 leaving out a 10 px band around its loose boundary, where depth and mask
  // disagree. The former default, grow + noDepth dynamic, gave 0.879 / 0.780 and 0.931 / 0.862).
  ScreeningMetrics m = evaluateScreening(f, r.mask, r.boxes);
  EXPECT_GT(m.dynamic_total, 400);
  EXPECT_GE(m.dynamicRecall(), 0.88);
  EXPECT_GE(m.staticRetention(), 0.82);
  ScreeningMetrics core = evaluateScreening(f, r.mask, r.boxes, 10);
  EXPECT_GE(core.dynamicRecall(), 0.93);
  EXPECT_GE(core.staticRetention(), 0.93);
  std::printf("real frame, defaults: recall %.3f retention %.3f; 10 px border left out: %.3f %.3f\n",
              m.dynamicRecall(), m.staticRetention(), core.dynamicRecall(), core.staticRetention());
}

TEST(RealFrame, SilhouetteRuleTakesOutlinesAndKeepsDeskAndWall) {
  // The real depth is misregistered with the colour by a few pixels and loses the outlines:
  // with the depth image, the silhouette rule (default radius 2 px) drops more of the people and
  // the hand-annotated static regions stay untouched.
  const Real& r = real();
  ASSERT_GT(r.frame.size(), 500u);
  ScreeningOptions o;
  features::FeatureFrame without = r.frame, with = r.frame;
  Screener(o).screen(without, r.boxes);
  const ScreeningStats st = Screener(o).screen(with, r.boxes, r.depth_m);
  EXPECT_GT(st.silhouette, 0);
  for (const cv::Rect& still : {kMonitor, kPartition, kWallTop}) {
    auto c = countIn(with, still);
    EXPECT_GE(c.first, 8);
    EXPECT_EQ(c.second, 0) << "static region " << still;
  }
  const ScreeningMetrics a = evaluateScreening(without, r.mask, r.boxes);
  const ScreeningMetrics b = evaluateScreening(with, r.mask, r.boxes);
  std::printf("real frame, silhouette rule: recall %.3f -> %.3f, retention %.3f -> %.3f (%d dropped by it)\n",
              a.personRecall(), b.personRecall(), a.staticRetention(), b.staticRetention(), st.silhouette);
  EXPECT_GT(b.personRecall(), a.personRecall());
  EXPECT_GE(b.personRecall(), 0.94);  // 0.908 -> 0.952 against the published mask
  EXPECT_GE(b.staticRetention(), 0.75);
}

TEST(RealFrame, DepthProbeTradesOutlineRecallForRetention) {
  // The depth probe for keypoints without depth (Screening.noDepthProbeRadius, off by default)
  // on real depth: the hand-annotated people stay dropped and the static regions kept, static
  // retention rises, but recall on the published mask falls (0.952 -> 0.919 at 8 px): the real
  // depth is misregistered with the colour, so an outline keypoint's nearest valid depth is
  // often the background behind the person. This is why the probe is not the default.
  const Real& r = real();
  ASSERT_GT(r.frame.size(), 500u);
  ScreeningOptions o;
  features::FeatureFrame without = r.frame, with = r.frame;
  Screener(o).screen(without, r.boxes, r.depth_m);
  o.no_depth_probe_radius_px = 8;
  Screener(o).screen(with, r.boxes, r.depth_m);
  for (const cv::Rect& person : {kRightShirt, kLeftTorso}) {
    auto c = countIn(with, person);
    EXPECT_EQ(c.second, c.first) << "person region " << person;
  }
  for (const cv::Rect& still : {kMonitor, kPartition, kWallTop}) EXPECT_EQ(countIn(with, still).second, 0);
  const ScreeningMetrics a = evaluateScreening(without, r.mask, r.boxes);
  const ScreeningMetrics b = evaluateScreening(with, r.mask, r.boxes);
  std::printf("real frame, depth probe 8 px: recall %.3f -> %.3f, retention %.3f -> %.3f\n",
              a.personRecall(), b.personRecall(), a.staticRetention(), b.staticRetention());
  EXPECT_GT(b.staticRetention(), a.staticRetention() + 0.05);
  EXPECT_LT(b.personRecall(), a.personRecall());
  EXPECT_GE(b.personRecall(), 0.90);
}

TEST(RealFrame, PaperThresholdReadAsSquareMetresSwallowsTheDesk) {
  // nThre = 0.43 m^2 accepts a third point up to sqrt(4.5 * 0.43) = 1.39 m from a tight pair:
  // the sitting person (2 m) merges with the desk and partition (3 m).
  const Real& r = real();
  ASSERT_GT(r.frame.size(), 500u);
  features::FeatureFrame f = r.frame;
  ScreeningOptions o;
  o.variant = ScreeningVariant::Paper;
  o.variance_threshold_m2 = 0.43;
  o.no_depth = ScreeningOptions::NoDepthRule::Dynamic;
  Screener(o).screen(f, r.boxes);
  auto monitor = countIn(f, kMonitor);
  auto partition = countIn(f, kPartition);
  EXPECT_EQ(monitor.second, monitor.first);
  EXPECT_EQ(partition.second, partition.first);
  ScreeningMetrics m = evaluateScreening(f, r.mask, r.boxes);
  EXPECT_GE(m.dynamicRecall(), 0.98);
  EXPECT_LE(m.staticRetention(), 0.3);
}

TEST(RealFrame, DetectModeDropsEverythingInBoxes) {
  const Real& r = real();
  ASSERT_GT(r.frame.size(), 500u);
  features::FeatureFrame f = r.frame;
  ScreeningOptions o;
  o.mode = DynamicMode::Detect;
  o.box_dilation = 0;
  ScreeningStats st = Screener(o).screen(f, r.boxes);
  EXPECT_EQ(st.kept, 0);
  EXPECT_EQ(st.dropped, st.in_boxes);
  ScreeningMetrics m = evaluateScreening(f, r.mask, r.boxes);
  EXPECT_DOUBLE_EQ(m.dynamicRecall(), 1.0);
  EXPECT_DOUBLE_EQ(m.staticRetention(), 0.0);
  EXPECT_EQ(m.static_dropped, m.static_in_boxes);  // nothing outside the boxes is touched
}
