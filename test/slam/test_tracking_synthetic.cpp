// End to end: a short synthetic static_xyz sequence (sim library, generated in memory) through
// System; every frame tracked and the ATE (eval module, TUM evaluate_ate) under a bound.
// Sequential mode (System.sequential): the result does not depend on thread timing, so the bound
// is tight. Measured: 80 frames -> ATE RMSE 4.1 mm, 9 keyframes.
#include "yolo_slam/common/config.h"
#include "yolo_slam/eval/ate.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

TEST(SlamTracking, SyntheticStaticXyzAteBound) {
  sim::SynthOptions so;
  so.preset = "static_xyz";
  so.frames = 80;
  so.seed = 3;
  sim::SequenceGenerator gen(so);
  ASSERT_EQ(gen.size(), 80u);

  slam::SystemOptions opt = slam::SystemOptions::load(Config());
  opt.screening.mode = screening::DynamicMode::Off;
  opt.sequential = true;  // no thread timing: the same result on every run
  slam::System sys(gen.camera(), opt, nullptr);
  Trajectory gt;
  int tracked = 0;
  for (size_t i = 0; i < gen.size(); ++i) {
    sim::SynthFrame f = gen.frame(i);
    gt.push_back({f.rgb_stamp, f.T_wc});
    slam::TrackResult r = sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {});
    if (r.state == slam::TrackingState::Ok) {
      ++tracked;
      EXPECT_TRUE(r.T_wc.matrix().allFinite());
    }
  }
  EXPECT_EQ(tracked, 80);
  const Trajectory est = sys.cameraTrajectory();
  ASSERT_EQ(est.size(), 80u);
  eval::AteResult ate = eval::computeAte(gt, est);
  std::printf("static_xyz 80 frames: ATE RMSE %.4f m, keyframes %zu\n", ate.stats.rmse, sys.stats().keyframes);
  EXPECT_LT(ate.stats.rmse, 0.006);
  const Trajectory kfs = sys.keyframeTrajectory();
  EXPECT_GE(kfs.size(), 2u);
}

namespace {

constexpr int kCloseFrames = 60;

struct KeyFrameRun {
  int tracked = 0;
  size_t inserted = 0;  // keyframes made, culled ones included
};

// The close-point criterion made to hold on every frame (any tracked count is "few", any
// untracked point "many"), so that only closeMinFrames spaces the keyframes.
KeyFrameRun runAlwaysClose(int close_min_frames) {
  sim::SynthOptions so;
  so.preset = "static_xyz";
  so.frames = kCloseFrames;
  so.seed = 7;
  sim::SequenceGenerator gen(so);
  slam::SystemOptions opt = slam::SystemOptions::load(Config());
  opt.screening.mode = screening::DynamicMode::Off;
  opt.sequential = true;
  opt.slam.tracking.close_tracked_max = 1 << 20;
  opt.slam.tracking.close_untracked_min = 0;
  opt.slam.tracking.close_min_frames = close_min_frames;
  slam::System sys(gen.camera(), opt, nullptr);
  KeyFrameRun run;
  for (size_t i = 0; i < gen.size(); ++i) {
    sim::SynthFrame f = gen.frame(i);
    if (sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {}).state == slam::TrackingState::Ok) ++run.tracked;
  }
  run.inserted = sys.stats().keyframes + sys.stats().keyframes_culled;
  return run;
}

}  // namespace

// With 0 (ORB-SLAM2) every frame becomes a keyframe; with 5 a young map (its first
// Tracking.youngMapFrames = 30 frames) still does, a mature one every fifth frame:
// about 30 + 30 / 5.
TEST(SlamTracking, CloseMinFramesSpacesCloseKeyFramesOfAMatureMap) {
  const KeyFrameRun orb = runAlwaysClose(0);
  const KeyFrameRun spaced = runAlwaysClose(5);
  std::printf("keyframes made: closeMinFrames 0 -> %zu, 5 -> %zu\n", orb.inserted, spaced.inserted);
  EXPECT_EQ(orb.tracked, kCloseFrames);
  EXPECT_EQ(spaced.tracked, kCloseFrames);
  EXPECT_GE(orb.inserted, static_cast<size_t>(kCloseFrames - 2));
  EXPECT_GE(spaced.inserted, 30u + 5u);
  EXPECT_LE(spaced.inserted, 30u + 8u);
}
