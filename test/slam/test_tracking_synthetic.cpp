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
