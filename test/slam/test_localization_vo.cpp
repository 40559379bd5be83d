// Localization mode's temporary points (Tracking.voPoints, voBelowMapPoints): made only when the
// last frame tracked few map points, and never of a keypoint the frame-to-frame evidence saw
// move. A synthetic static_xyz run is mapped, then tracked in localization mode; sequential
// mode, so the runs are deterministic.
#include "yolo_slam/common/config.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/system.h"
#include "support/static_scene.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

namespace {

constexpr int kMappedFrames = 60;
constexpr int kLocalizedFrames = 30;

struct Outcome {
  size_t vo_frames = 0;
  size_t tracked = 0;
  size_t keyframes_added = 0;
};

// Maps static_xyz for kMappedFrames frames, then tracks kLocalizedFrames more in localization mode.
Outcome mapThenLocalize(int vo_below_map_points) {
  sim::SequenceGenerator gen(test_support::staticXyz(kMappedFrames + kLocalizedFrames, 4));
  slam::SystemOptions opt = test_support::plainSequentialOptions();
  opt.slam.tracking.vo_below_map_points = vo_below_map_points;
  slam::System sys(gen.camera(), opt, nullptr);
  const features::OrbExtractor orb{features::OrbOptions::load(Config())};
  size_t keyframes = 0;
  Outcome out;
  for (int i = 0; i < kMappedFrames + kLocalizedFrames; ++i) {
    if (i == kMappedFrames) {
      keyframes = sys.stats().keyframes;
      sys.setLocalizationOnly(true);
    }
    const sim::SynthFrame s = gen.frame(i);
    const features::FeatureFrame f = features::buildFeatureFrame(orb, gen.camera(), s.bgr, s.depth, s.rgb_stamp);
    const bool ok = sys.trackFeatures(f).state == slam::TrackingState::Ok;
    EXPECT_TRUE(ok) << "frame " << i;
    if (i >= kMappedFrames) out.tracked += ok ? 1 : 0;
  }
  const slam::SystemStats st = sys.stats();
  out.vo_frames = st.vo_frames;
  out.keyframes_added = st.keyframes - keyframes;
  return out;
}

slam::Frame markedFrame(std::vector<int8_t> motion, std::vector<uint8_t> boxed) {
  slam::Frame F;
  F.N = static_cast<int>(std::max(motion.size(), boxed.size()));
  F.motion = std::move(motion);
  F.boxed = std::move(boxed);
  return F;
}

}  // namespace

TEST(SlamLocalizationVo, NoTemporaryPointsWhileTheMapCarriesTheFrame) {
  EXPECT_EQ(slam::TrackingOptions{}.vo_below_map_points, 50);
  const Outcome def = mapThenLocalize(slam::TrackingOptions{}.vo_below_map_points);
  EXPECT_EQ(def.tracked, static_cast<size_t>(kLocalizedFrames));
  EXPECT_EQ(def.keyframes_added, 0u);
  EXPECT_EQ(def.vo_frames, 0u);
  // ORB-SLAM2's rule (temporary points on every frame) does make them here.
  const Outcome orbslam2 = mapThenLocalize(1 << 30);
  EXPECT_EQ(orbslam2.tracked, static_cast<size_t>(kLocalizedFrames));
  EXPECT_GE(orbslam2.vo_frames, static_cast<size_t>(kLocalizedFrames - 1));
}

TEST(SlamLocalizationVo, SeenMovingFollowsTheFrameToFrameEvidence) {
  // motion: 1 static-consistent, 0 moved, -1 untested; boxed: kept static inside a person box.
  const slam::Frame F = markedFrame({1, 0, -1, 1, 0, -1}, {0, 0, 0, 1, 1, 1});
  const bool expected[] = {false, true, false, false, true, true};
  for (int i = 0; i < F.N; ++i) EXPECT_EQ(F.seenMoving(i), expected[i]) << "keypoint " << i;
  // Without the evidence nothing is seen moving, except what a box holds unconfirmed.
  const slam::Frame untested = markedFrame({}, {0, 1});
  EXPECT_FALSE(untested.seenMoving(0));
  EXPECT_TRUE(untested.seenMoving(1));
  const slam::Frame unboxed = markedFrame({0, 1}, {});
  EXPECT_TRUE(unboxed.seenMoving(0));
  EXPECT_FALSE(unboxed.seenMoving(1));
}
