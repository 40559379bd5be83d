// Loop closing end to end on the synthetic `loop` preset (the camera circles the room and comes
// back to its start), subsampled to 5 fps so the whole circle fits in a short test. Two systems
// see the same rendered frames, one with LoopClosing.enabled = false: with loop closing a loop
// is closed between the last keyframes and the first ones and the ATE is lower.
// The room's repeated textures also produce geometrically consistent false loops (~100 deg
// away); the drift bound (LoopClosing.maxCorrectionDeg) must reject them, else the ATE explodes.
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/eval/ate.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include "support/loop_preset.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

TEST(SlamLoopClosing, LoopPresetDetectsLoopAndLowersAte) {
  auto voc = test_support::shippedVocabulary();
  sim::SequenceGenerator gen(test_support::loopPreset());

  slam::SystemOptions opt = slam::SystemOptions::load(Config());
  opt.screening.mode = screening::DynamicMode::Off;
  opt.sequential = true;  // mapping keeps up with every frame, as at 5 fps in real time
  slam::SystemOptions opt_off = opt;
  opt_off.slam.loop.enabled = false;
  ASSERT_TRUE(opt.slam.loop.enabled);  // the default
  slam::System on(gen.camera(), opt, voc), off(gen.camera(), opt_off, voc);

  Trajectory gt;
  size_t tracked_on = 0, tracked_off = 0;
  for (size_t i = 0; i < gen.size(); ++i) {
    sim::SynthFrame f = gen.frame(i);
    gt.push_back({f.rgb_stamp, f.T_wc});
    tracked_on += on.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {}).state == slam::TrackingState::Ok;
    tracked_off += off.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {}).state == slam::TrackingState::Ok;
  }
  const double ate_on = eval::computeAte(gt, on.cameraTrajectory()).stats.rmse;
  const double ate_off = eval::computeAte(gt, off.cameraTrajectory()).stats.rmse;
  const auto loops = on.loops();
  std::printf("loop preset %zu frames: loop closing off: tracked %zu, ATE RMSE %.4f m; on: tracked %zu, "
              "loops %zu, ATE RMSE %.4f m\n", gen.size(), tracked_off, ate_off, tracked_on, loops.size(), ate_on);
  EXPECT_TRUE(off.loops().empty());
  ASSERT_GE(loops.size(), 1u);
  // The loop joins the end of the circle to its beginning: keyframe ids far apart.
  EXPECT_GT(loops.front().first - loops.front().second, 30);
  EXPECT_EQ(on.stats().loops_closed, loops.size());
  EXPECT_GE(tracked_on, tracked_off);
  EXPECT_LT(ate_on, ate_off);
  EXPECT_LT(ate_on, 0.011);  // measured (sequential): 7.3 mm, off 14.6 mm
}
