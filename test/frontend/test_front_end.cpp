// The frame front end: depth cleaning, extraction and screening of one RGB-D pair with boxes.
#include "yolo_slam/common/error.h"
#include "yolo_slam/frontend/front_end.h"

#include "support/images.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <future>
#include <limits>

using namespace yolo_slam;

namespace {

cv::Mat texture(unsigned seed) { return test_support::texturedImage(seed); }

// A wall 3 m away with a "person" 1.2 m away in the box region.
const cv::Rect kPerson(260, 120, 120, 300);

cv::Mat wallWithPerson() {
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(3.0f));
  depth(kPerson).setTo(1.2f);
  return depth;
}

detection::Box personBox() {
  detection::Box b;
  b.rect = cv::Rect2f(kPerson.x, kPerson.y, kPerson.width, kPerson.height);
  b.score = 0.9f;
  b.label = "person";
  return b;
}

frontend::FrontEnd makeFrontEnd(screening::DynamicMode mode) {
  screening::ScreeningOptions s;
  s.mode = mode;
  return frontend::FrontEnd(features::OrbOptions(), s);
}

}  // namespace

TEST(FrontEnd, ScreensThePersonInItsBoxAndKeepsTheWall) {
  frontend::FrontEnd fe = makeFrontEnd(screening::DynamicMode::DetectGeometry);
  const frontend::FrontEndResult r = fe.process(texture(1), wallWithPerson(), 0.0, {personBox()}, CameraModel());
  ASSERT_GT(r.frame.size(), 200u);
  ASSERT_EQ(r.frame.dynamic.size(), r.frame.size());
  int person = 0, person_dropped = 0, wall_dropped = 0;
  for (size_t i = 0; i < r.frame.size(); ++i) {
    const bool on_person = kPerson.contains(r.frame.keypoints[i].pt);
    person += on_person;
    person_dropped += on_person && r.frame.dynamic[i];
    wall_dropped += !on_person && r.frame.dynamic[i];
  }
  EXPECT_GT(person, 20);
  EXPECT_GT(person_dropped, person * 9 / 10);
  EXPECT_LT(wall_dropped, static_cast<int>(r.frame.size()) / 20);
  EXPECT_EQ(r.stats.screening.dropped, person_dropped + wall_dropped);
  ASSERT_EQ(r.boxes.size(), 1u);
  EXPECT_GT(r.stats.extraction_ms, 0.0);
}

TEST(FrontEnd, InvalidDepthReadingsAreNoDepth) {
  frontend::FrontEnd fe = makeFrontEnd(screening::DynamicMode::Off);
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.0f));
  depth.colRange(0, 320).setTo(std::numeric_limits<float>::quiet_NaN());
  depth.rowRange(0, 240).colRange(320, 640).setTo(std::numeric_limits<float>::infinity());
  depth.rowRange(240, 480).colRange(320, 480).setTo(-1.0f);
  const frontend::FrontEndResult r = fe.process(texture(2), depth, 0.0, {}, CameraModel());
  ASSERT_GT(r.frame.size(), 200u);
  int with_depth = 0;
  for (size_t i = 0; i < r.frame.size(); ++i) {
    const cv::Point px(cvRound(r.frame.keypoints[i].pt.x), cvRound(r.frame.keypoints[i].pt.y));
    const float raw = depth.at<float>(px);
    const float d = r.frame.depth[i];
    EXPECT_TRUE(std::isfinite(d));
    if (std::isfinite(raw) && raw > 0) EXPECT_FLOAT_EQ(d, raw);
    else EXPECT_LE(d, 0.0f) << "keypoint at " << px << " read the invalid reading " << raw << " as " << d;
    with_depth += d > 0;
  }
  EXPECT_GT(with_depth, 0);
  // The caller's depth image is not modified.
  EXPECT_TRUE(std::isnan(depth.at<float>(0, 0)));
}

TEST(FrontEnd, BadInputIsAnError) {
  frontend::FrontEnd fe = makeFrontEnd(screening::DynamicMode::DetectGeometry);
  EXPECT_THROW(fe.process(cv::Mat(), cv::Mat(), 0.0, {}, CameraModel()), Error);
  const cv::Mat wrong_type(480, 640, CV_16UC1, cv::Scalar(2000));
  EXPECT_THROW(fe.process(texture(3), wrong_type, 0.0, {}, CameraModel()), Error);
  const cv::Mat wrong_size(240, 320, CV_32F, cv::Scalar(2.0f));
  try {
    fe.process(texture(3), wrong_size, 1.5, {}, CameraModel());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("320x240"), std::string::npos) << e.what();
  }
  // No depth at all is allowed: every keypoint without depth.
  const frontend::FrontEndResult r = fe.process(texture(3), cv::Mat(), 2.0, {}, CameraModel());
  EXPECT_GT(r.frame.size(), 200u);
}

TEST(FrontEnd, BadOptionsAreRejectedAtConstruction) {
  screening::ScreeningOptions s;
  s.probability = 2.0;
  EXPECT_THROW(frontend::FrontEnd(features::OrbOptions(), s), Error);
  features::OrbOptions o;
  o.n_features = 0;
  EXPECT_THROW(frontend::FrontEnd(o, screening::ScreeningOptions()), Error);
}

namespace {

// A box over the left `box_width` pixels of the image, its content 1.2 m away: screening drops
// the keypoints in it (about half of them for a box over half of the image).
size_t keypointsOfTheSecondFrame(double boost_max, double* budget, int box_width = 320) {
  features::OrbOptions orb;
  orb.dynamic_boost_max = boost_max;
  screening::ScreeningOptions s;
  s.mode = screening::DynamicMode::Detect;
  frontend::FrontEnd fe(orb, s);
  detection::Box half;
  half.rect = cv::Rect2f(0, 0, static_cast<float>(box_width), 480);
  half.score = 0.9f;
  half.label = "person";
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(3.0f));
  depth(cv::Rect(0, 0, box_width, 480)).setTo(1.2f);
  const frontend::FrontEndResult first = fe.process(texture(7), depth, 0.0, {half}, CameraModel());
  // The first frame is extracted again with the budget it turned out to need (none for a
  // narrow box).
  if (box_width == 320) EXPECT_DOUBLE_EQ(first.stats.feature_budget, boost_max);
  if (box_width <= 160) EXPECT_DOUBLE_EQ(first.stats.feature_budget, 1.0);
  EXPECT_GT(first.frame.countDynamic(), first.frame.size() * box_width / 640 / 2);
  const frontend::FrontEndResult second = fe.process(texture(8), depth, 0.033, {half}, CameraModel());
  *budget = second.stats.feature_budget;
  return second.frame.size();
}

}  // namespace

TEST(FrontEnd, ExtractsMoreWhenScreeningDroppedMuchOfTheLastFrame) {
  double fixed_budget = 0, boosted_budget = 0;
  const size_t fixed = keypointsOfTheSecondFrame(1.0, &fixed_budget);
  const size_t boosted = keypointsOfTheSecondFrame(2.0, &boosted_budget);
  EXPECT_DOUBLE_EQ(fixed_budget, 1.0);
  // About half was dropped: about twice the keypoints, so that about nFeatures stay.
  EXPECT_GE(boosted_budget, 1.75);
  EXPECT_LE(boosted_budget, 2.0);
  EXPECT_GT(boosted, fixed * 3 / 2);
  // A small drop (an eighth of the view) keeps ORB-SLAM2's budget.
  double small_budget = 0;
  keypointsOfTheSecondFrame(2.0, &small_budget, 80);
  EXPECT_DOUBLE_EQ(small_budget, 1.0);
}

TEST(FrontEnd, DefaultBudgetGrowsPastTwiceWhenPeopleFillTwoThirdsOfTheView) {
  // A crowd: a box over 70 % of the view drops about 70 % of the keypoints. Twice nFeatures
  // would leave about 0.6 nFeatures for SLAM; the default allows more.
  double budget = 0;
  const size_t crowded = keypointsOfTheSecondFrame(features::OrbOptions().dynamic_boost_max, &budget, 448);
  double capped_budget = 0;
  const size_t capped = keypointsOfTheSecondFrame(2.0, &capped_budget, 448);
  EXPECT_DOUBLE_EQ(capped_budget, 2.0);
  EXPECT_GT(budget, 2.5);
  EXPECT_GT(crowded, capped * 5 / 4);
}

TEST(FrontEnd, RejectsABoostBelowOne) {
  features::OrbOptions orb;
  orb.dynamic_boost_max = 0.5;
  EXPECT_THROW(frontend::FrontEnd(orb, screening::ScreeningOptions()), Error);
}

TEST(FrontEnd, FramesBeforeTheFirstDetectionAreMarkedAwaitingIt) {
  frontend::FrontEnd fe = makeFrontEnd(screening::DynamicMode::DetectGeometry);
  EXPECT_TRUE(fe.process(texture(1), wallWithPerson(), 0.0, {}, CameraModel(), false).awaiting_detection);
  EXPECT_TRUE(fe.process(texture(1), wallWithPerson(), 0.033, {}, CameraModel(), false).awaiting_detection);
  // The detector's first result, even one without people, ends the wait for good.
  EXPECT_FALSE(fe.process(texture(1), wallWithPerson(), 0.066, {}, CameraModel(), true).awaiting_detection);
  EXPECT_FALSE(fe.process(texture(1), wallWithPerson(), 0.1, {}, CameraModel(), false).awaiting_detection);
  fe.clear();  // a map reset: the box tracker starts empty again
  EXPECT_TRUE(fe.process(texture(1), wallWithPerson(), 0.133, {}, CameraModel(), false).awaiting_detection);
}

TEST(FrontEnd, ModesWithoutBoxesNeverAwaitADetection) {
  for (auto mode : {screening::DynamicMode::Off, screening::DynamicMode::Geometry}) {
    frontend::FrontEnd fe = makeFrontEnd(mode);
    EXPECT_FALSE(fe.process(texture(1), wallWithPerson(), 0.0, {}, CameraModel(), false).awaiting_detection);
  }
}

TEST(FrontEnd, ExtractingTheNextFrameOnAnotherThreadScreensAsProcessDoes) {
  // yolo_slam_run extracts frame k+1 on a worker while frame k is screened and tracked.
  frontend::FrontEnd serial = makeFrontEnd(screening::DynamicMode::DetectGeometry);
  frontend::FrontEnd ahead = makeFrontEnd(screening::DynamicMode::DetectGeometry);
  const int kFrames = 4;
  std::future<frontend::Extracted> next = std::async(std::launch::async, [&] {
    return ahead.extract(texture(20), wallWithPerson(), 0.0, CameraModel());
  });
  for (int k = 0; k < kFrames; ++k) {
    frontend::Extracted ex = next.get();
    if (k + 1 < kFrames)
      next = std::async(std::launch::async, [&, k] {
        return ahead.extract(texture(21 + k), wallWithPerson(), (k + 1) / 30.0, CameraModel());
      });
    const frontend::FrontEndResult a = ahead.screen(std::move(ex), {personBox()}, CameraModel());
    const frontend::FrontEndResult b =
        serial.process(texture(20 + k), wallWithPerson(), k / 30.0, {personBox()}, CameraModel());
    ASSERT_EQ(a.frame.size(), b.frame.size()) << "frame " << k;
    EXPECT_EQ(a.frame.dynamic, b.frame.dynamic) << "frame " << k;
    EXPECT_EQ(a.frame.depth, b.frame.depth) << "frame " << k;
    EXPECT_GT(a.frame.countDynamic(), 20u) << "frame " << k;
    EXPECT_EQ(a.boxes.size(), b.boxes.size()) << "frame " << k;
    EXPECT_GT(a.stats.extraction_ms, 0.0);
  }
}

TEST(FrontEnd, ExtractRefusesWhatProcessRefuses) {
  const frontend::FrontEnd fe = makeFrontEnd(screening::DynamicMode::DetectGeometry);
  EXPECT_THROW(fe.extract(cv::Mat(), wallWithPerson(), 0.0, CameraModel()), Error);
  EXPECT_THROW(fe.extract(texture(1), cv::Mat(100, 100, CV_32F, cv::Scalar(2.0f)), 0.0, CameraModel()), Error);
}
