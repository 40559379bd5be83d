// System robustness to bad per-frame input: no depth, black/saturated images, NaN depth,
// mismatched depth, empty images, timestamp jumps. Tracking reports lost (or not initialised),
// never crashes and never outputs a non-finite pose.
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/frontend/front_end.h"
#include "yolo_slam/slam/system.h"

#include "support/images.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>

using namespace yolo_slam;
using namespace yolo_slam::slam;

namespace {

SystemOptions offOptions() {
  SystemOptions o = SystemOptions::load(Config());
  o.screening.mode = screening::DynamicMode::Off;
  return o;
}

// A textured image (smoothed noise) and a plane 2 m away.
cv::Mat texture(unsigned seed) { return test_support::texturedImage(seed); }

void expectFinite(const Trajectory& t) {
  for (const auto& p : t) {
    EXPECT_TRUE(std::isfinite(p.stamp));
    EXPECT_TRUE(p.T_wc.matrix().allFinite());
  }
}

}  // namespace

TEST(SlamSystem, BadFramesReportLostWithoutCrash) {
  CameraModel cam;
  System sys(cam, offOptions(), nullptr);
  const cv::Mat img = texture(1);
  const cv::Mat plane(480, 640, CV_32F, cv::Scalar(2.0f));
  double t = 0;
  auto track = [&](const cv::Mat& im, const cv::Mat& d) {
    t += 1.0 / 30;
    return sys.trackRgbd(im, d, t, {});
  };
  // Before initialisation: no depth, black, saturated, NaN depth, wrong depth size, empty image.
  EXPECT_NE(track(img, cv::Mat()).state, TrackingState::Ok);
  EXPECT_NE(track(cv::Mat::zeros(480, 640, CV_8UC3), plane).state, TrackingState::Ok);
  EXPECT_NE(track(cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(255)), plane).state, TrackingState::Ok);
  cv::Mat nan_depth(480, 640, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_NE(track(img, nan_depth).state, TrackingState::Ok);
  EXPECT_NE(track(img, cv::Mat(100, 100, CV_32F, cv::Scalar(2.0f))).state, TrackingState::Ok);
  EXPECT_NE(track(cv::Mat(), plane).state, TrackingState::Ok);
  EXPECT_NE(track(img, cv::Mat(480, 640, CV_16U, cv::Scalar(1000))).state, TrackingState::Ok);
  EXPECT_TRUE(sys.cameraTrajectory().empty());

  // A good frame initialises; the same view again tracks.
  TrackResult r = track(img, plane);
  ASSERT_EQ(r.state, TrackingState::Ok);
  EXPECT_TRUE(r.T_wc.matrix().allFinite());
  EXPECT_EQ(track(img, plane).state, TrackingState::Ok);

  // After initialisation: black frames are lost, then the view comes back and is tracked
  // again (against the last keyframe), also across a timestamp jump.
  for (int k = 0; k < 3; ++k) {
    TrackResult lost = track(cv::Mat::zeros(480, 640, CV_8UC3), plane);
    EXPECT_EQ(lost.state, TrackingState::Lost);
  }
  EXPECT_EQ(track(img, nan_depth).state == TrackingState::Ok ||
                track(img, nan_depth).state == TrackingState::Lost,
            true);
  t += 100.0;  // jump in timestamps
  TrackResult back = track(img, plane);
  EXPECT_EQ(back.state, TrackingState::Ok);
  // A timestamp going backwards is handled too.
  t -= 50.0;
  EXPECT_NE(track(img, plane).state, TrackingState::NotInitialized);

  sys.waitForLocalMapping();
  const Trajectory traj = sys.cameraTrajectory();
  expectFinite(traj);
  expectFinite(sys.keyframeTrajectory());
  SystemStats s = sys.stats();
  EXPECT_EQ(s.frames, s.tracked + s.lost);
  EXPECT_EQ(traj.size(), s.tracked);
  EXPECT_GE(s.lost, 10u);
  // Shutdown is idempotent, tracking after it is refused politely.
  sys.shutdown();
  sys.shutdown();
  EXPECT_NE(sys.trackRgbd(img, plane, t + 1, {}).state, TrackingState::Ok);
}

TEST(SlamSystem, ResetAndLocalizationMode) {
  CameraModel cam;
  System sys(cam, offOptions(), nullptr);
  const cv::Mat img = texture(2);
  const cv::Mat plane(480, 640, CV_32F, cv::Scalar(2.0f));
  ASSERT_EQ(sys.trackRgbd(img, plane, 0.0, {}).state, TrackingState::Ok);
  sys.waitForLocalMapping();
  EXPECT_GE(sys.stats().keyframes, 1u);
  EXPECT_GT(sys.mapSnapshot().points.size(), 100u);
  sys.setLocalizationOnly(true);
  EXPECT_TRUE(sys.localizationOnly());
  for (int k = 1; k <= 5; ++k) EXPECT_EQ(sys.trackRgbd(img, plane, k / 30.0, {}).state, TrackingState::Ok);
  sys.setLocalizationOnly(false);
  sys.reset();
  EXPECT_EQ(sys.stats().keyframes, 0u);
  EXPECT_TRUE(sys.cameraTrajectory().empty());
  EXPECT_EQ(sys.trackRgbd(img, plane, 1.0, {}).state, TrackingState::Ok);
  const std::string text = sys.statsJson();
  EXPECT_EQ(text.back(), '\n');
  const Json js = parseJson(text, "statsJson");
  EXPECT_EQ(js["frames"], 7) << text;
  // The members yolo_slam_run's stats.json shares: counts, screening sections, timings.
  for (const char* key : {"map_resets", "keypoints", "temporal", "boxes_screened", "timings"})
    EXPECT_TRUE(js.contains(key)) << key << " missing in " << text;
  EXPECT_EQ(js["timings"]["extraction_plus_tracking"]["count"], 7) << text;
  EXPECT_EQ(js["keypoints"]["in_boxes"], 0) << text;
}

TEST(SlamSystem, TrackRgbdScreensThroughTheFrontEnd) {
  // The runner (System::trackRgbd) and the Screening nodelet (FrontEnd) screen a frame alike.
  const SystemOptions opt = SystemOptions::load(Config());
  System sys(CameraModel(), opt, nullptr);
  frontend::FrontEnd fe(opt.orb, opt.screening);
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(3.0f));
  const cv::Rect person(250, 100, 140, 320);
  depth(person).setTo(1.3f);
  depth.at<float>(10, 10) = std::numeric_limits<float>::quiet_NaN();
  detection::Box box;
  box.rect = cv::Rect2f(person);
  box.score = 0.9f;
  for (int k = 0; k < 3; ++k) {
    const cv::Mat img = texture(10 + k);
    sys.trackRgbd(img, depth, k / 30.0, {box});
    const features::FeatureFrame a = sys.lastFrame();
    const features::FeatureFrame b = fe.process(img, depth, k / 30.0, {box}, CameraModel()).frame;
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(a.dynamic, b.dynamic) << "frame " << k;
    EXPECT_EQ(a.depth, b.depth) << "frame " << k;
    EXPECT_GT(std::count(a.dynamic.begin(), a.dynamic.end(), 1), 10) << "frame " << k;
  }
}

TEST(SlamSystem, FramesExtractedAheadOnAnotherThreadAreScreenedAsTrackRgbdScreensThem) {
  // yolo_slam_run (not --sequential) extracts frame k+1 while frame k is screened and tracked.
  const SystemOptions opt = SystemOptions::load(Config());
  System serial(CameraModel(), opt, nullptr), ahead(CameraModel(), opt, nullptr);
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(3.0f));
  const cv::Rect person(250, 100, 140, 320);
  depth(person).setTo(1.3f);
  detection::Box box;
  box.rect = cv::Rect2f(person);
  box.score = 0.9f;
  const int kFrames = 4;
  auto extractAsync = [&](int k) {
    return std::async(std::launch::async, [&, k] { return ahead.extractFrame(texture(30 + k), depth, k / 30.0); });
  };
  std::future<ExtractedFrame> next = extractAsync(0);
  for (int k = 0; k < kFrames; ++k) {
    ExtractedFrame ef = next.get();
    if (k + 1 < kFrames) next = extractAsync(k + 1);
    const TrackResult a = ahead.trackExtracted(std::move(ef), {box});
    const TrackResult b = serial.trackRgbd(texture(30 + k), depth, k / 30.0, {box});
    EXPECT_EQ(a.state, b.state) << "frame " << k;
    const features::FeatureFrame fa = ahead.lastFrame(), fb = serial.lastFrame();
    ASSERT_EQ(fa.size(), fb.size()) << "frame " << k;
    EXPECT_EQ(fa.dynamic, fb.dynamic) << "frame " << k;
  }
  EXPECT_EQ(ahead.stats().frames, static_cast<size_t>(kFrames));
}

TEST(SlamSystem, AFrameTheFrontEndRefusesAheadIsReportedLost) {
  System sys(CameraModel(), offOptions(), nullptr);
  const cv::Mat plane(480, 640, CV_32F, cv::Scalar(2.0f));
  ExtractedFrame ef = sys.extractFrame(cv::Mat(), plane, 0.0);
  EXPECT_NE(ef.error.find("empty image"), std::string::npos) << ef.error;
  EXPECT_NE(sys.trackExtracted(std::move(ef), {}).state, TrackingState::Ok);
  EXPECT_EQ(sys.trackExtracted(sys.extractFrame(texture(3), plane, 0.033), {}).state, TrackingState::Ok);
  const SystemStats s = sys.stats();
  EXPECT_EQ(s.frames, 2u);
  EXPECT_EQ(s.lost, 1u);
  EXPECT_THROW(sys.extractFrame(cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(0)), plane, 0.066), Error);
}
