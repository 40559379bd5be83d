// The dense map inside slam::System (DenseMap.enabled, sequential so the run is deterministic):
// every keyframe reaches the dense mapper, a closed loop and its global BA make it rebuild the
// map from the corrected poses, and a reset empties it.
#include "yolo_slam/common/config.h"
#include "yolo_slam/mapping/dense_mapper.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"

#include "support/loop_preset.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

TEST(SlamDenseMap, KeyFramesReachTheMapAndALoopRebuildsIt) {
  auto voc = test_support::shippedVocabulary();
  sim::SequenceGenerator gen(test_support::loopPreset());
  slam::SystemOptions opt = slam::SystemOptions::load(Config());
  opt.screening.mode = screening::DynamicMode::Off;
  opt.sequential = true;
  opt.dense.enabled = true;
  opt.dense.final_rebuild = false;  // count the rebuilds the loop asked for
  opt.dense.resolution_m = 0.1;     // coarse and sparse: the test is about the flow, not the map
  opt.dense.pixel_stride = 8;
  slam::System sys(gen.camera(), opt, voc);
  ASSERT_NE(sys.denseMap(), nullptr);
  size_t keyframes_made = 0;
  for (size_t i = 0; i < gen.size(); ++i) {
    sim::SynthFrame f = gen.frame(i);
    keyframes_made += sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {}).keyframe_inserted ? 1 : 0;
  }
  sys.shutdown();
  const slam::SystemStats s = sys.stats();
  const mapping::DenseMapStats d = sys.denseMap()->stats();
  ASSERT_GE(s.loops_closed, 1u) << "the fixture's loop was not closed";
  EXPECT_EQ(d.keyframes, keyframes_made);
  EXPECT_EQ(d.dropped, 0u);
  // The loop correction and its global BA each move the map version; sequential mode sees both.
  EXPECT_GE(d.rebuilds, 1u);
  EXPECT_LE(d.rebuilds, s.loops_closed + s.global_bas);
  EXPECT_GT(d.voxels, 100u);
  EXPECT_GT(d.points, d.voxels);
}

TEST(SlamDenseMap, OffByDefaultAndResetEmptiesIt) {
  sim::SynthOptions so;
  so.preset = "static_xyz";
  so.frames = 20;
  so.seed = 3;
  sim::SequenceGenerator gen(so);
  EXPECT_EQ(slam::System(gen.camera(), slam::SystemOptions::load(Config()), nullptr).denseMap(), nullptr);
  slam::SystemOptions opt = slam::SystemOptions::load(Config());
  opt.sequential = true;
  opt.dense.enabled = true;
  slam::System sys(gen.camera(), opt, nullptr);
  for (size_t i = 0; i < gen.size(); ++i) {
    sim::SynthFrame f = gen.frame(i);
    sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {});
  }
  ASSERT_GT(sys.denseMap()->stats().voxels, 0u);
  sys.reset();
  EXPECT_EQ(sys.denseMap()->stats().voxels, 0u);
}
