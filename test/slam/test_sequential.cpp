// System.sequential: local mapping, loop closing and the global BA after a loop run inline after
// each frame, so two systems fed the same frames produce bit-identical trajectories and maps.
// The sequence is the loop preset of test_loop_closing (the camera circles the room, a loop is
// closed near the end), so keyframe culling, loop correction and the global BA are all covered.
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/eval/ate.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include "support/loop_preset.h"

#include <gtest/gtest.h>

#include <cstdio>

using namespace yolo_slam;

namespace {

slam::SystemOptions sequentialOptions() {
  slam::SystemOptions o = slam::SystemOptions::load(Config());
  o.screening.mode = screening::DynamicMode::Off;
  o.sequential = true;
  return o;
}

// Every stamp and every matrix element equal (==, not within a tolerance).
void expectBitIdentical(const Trajectory& a, const Trajectory& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].stamp, b[i].stamp) << what << " pose " << i;
    const Eigen::Matrix4d& A = a[i].T_wc.matrix();
    const Eigen::Matrix4d& B = b[i].T_wc.matrix();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c)
        ASSERT_EQ(A(r, c), B(r, c)) << what << " pose " << i << " (" << r << ", " << c << ")";
  }
}

}  // namespace

TEST(SlamSequential, SettingsKeyDefaultsToThreaded) {
  EXPECT_FALSE(slam::SystemOptions::load(Config()).sequential);
  EXPECT_TRUE(slam::SystemOptions::load(Config::fromString("%YAML:1.0\nSystem.sequential: 1\n")).sequential);
  EXPECT_FALSE(slam::SystemOptions::load(Config::fromString("%YAML:1.0\nSystem.sequential: 0\n")).sequential);
  try {
    slam::SystemOptions::load(Config::fromString("%YAML:1.0\nSystem.sequential: \"maybe\"\n", "bad.yaml"));
    ADD_FAILURE() << "a non-boolean System.sequential was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("System.sequential"), std::string::npos) << e.what();
  }
  CameraModel cam;
  slam::System threaded(cam, slam::SystemOptions::load(Config()), nullptr);
  slam::System sequential(cam, sequentialOptions(), nullptr);
  EXPECT_FALSE(threaded.sequential());
  EXPECT_TRUE(sequential.sequential());
}

TEST(SlamSequential, LoopPresetTwiceBitIdentical) {
  auto voc = test_support::shippedVocabulary();
  sim::SequenceGenerator gen(test_support::loopPreset());

  const slam::SystemOptions opt = sequentialOptions();
  ASSERT_TRUE(opt.slam.loop.enabled && opt.slam.loop.global_ba);  // the defaults
  // Interleaved on the same frames: the two systems' objects live at different addresses, so
  // anything ordered by address would show.
  slam::System a(gen.camera(), opt, voc), b(gen.camera(), opt, voc);
  Trajectory gt;
  for (size_t i = 0; i < gen.size(); ++i) {
    sim::SynthFrame f = gen.frame(i);
    gt.push_back({f.rgb_stamp, f.T_wc});
    const slam::TrackResult ra = a.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {});
    const slam::TrackResult rb = b.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {});
    ASSERT_EQ(ra.state, rb.state) << "frame " << i;
  }
  a.shutdown();
  b.shutdown();
  const slam::SystemStats sa = a.stats(), sb = b.stats();
  const double ate = eval::computeAte(gt, a.cameraTrajectory()).stats.rmse;
  std::printf("loop preset %zu frames, sequential: tracked %zu, keyframes %zu (culled %zu), map points %zu, "
              "loops %zu, global BAs %zu, ATE RMSE %.4f m\n", gen.size(), sa.tracked, sa.keyframes,
              sa.keyframes_culled, sa.map_points, sa.loops_closed, sa.global_bas, ate);
  expectBitIdentical(a.cameraTrajectory(), b.cameraTrajectory(), "camera trajectory");
  expectBitIdentical(a.keyframeTrajectory(), b.keyframeTrajectory(), "keyframe trajectory");
  EXPECT_EQ(sa.tracked, sb.tracked);
  EXPECT_EQ(sa.keyframes, sb.keyframes);
  EXPECT_EQ(sa.keyframes_culled, sb.keyframes_culled);
  EXPECT_EQ(sa.map_points, sb.map_points);
  EXPECT_EQ(sa.relocalizations, sb.relocalizations);
  EXPECT_EQ(a.loops(), b.loops());
  EXPECT_EQ(sa.global_bas, sb.global_bas);
  // What the comparison is worth: a map with culling and a closed loop, its global BA done inline.
  EXPECT_GT(sa.keyframes, 20u);
  ASSERT_GE(sa.loops_closed, 1u);
  EXPECT_EQ(sa.global_bas, sa.loops_closed);
  EXPECT_EQ(sa.local_mapping_ms.size(), sa.keyframes + sa.keyframes_culled);
}

// Pause/resume (localization-only mode), reset and shutdown with the back end inline; after
// every frame local mapping has processed everything queued, so tracking sees it idle.
TEST(SlamSequential, LocalizationModeResetAndShutdown) {
  sim::SynthOptions so;
  so.preset = "static_xyz";
  so.frames = 60;
  so.seed = 3;
  sim::SequenceGenerator gen(so);
  slam::System sys(gen.camera(), sequentialOptions(), nullptr);
  const size_t kLocalizationFrom = 20, kLocalizationTo = 40;
  size_t keyframes_before_localization = 0;
  for (size_t i = 0; i < gen.size(); ++i) {
    if (i == kLocalizationFrom) {
      keyframes_before_localization = sys.stats().keyframes;
      sys.setLocalizationOnly(true);
    }
    if (i == kLocalizationTo) sys.setLocalizationOnly(false);
    sim::SynthFrame f = gen.frame(i);
    EXPECT_EQ(sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {}).state, slam::TrackingState::Ok) << "frame " << i;
    const slam::SystemStats s = sys.stats();
    EXPECT_EQ(s.local_mapping_ms.size(), s.keyframes + s.keyframes_culled) << "frame " << i;
    if (i >= kLocalizationFrom && i < kLocalizationTo) {
      EXPECT_EQ(s.keyframes, keyframes_before_localization) << "frame " << i;
    }
  }
  EXPECT_GE(keyframes_before_localization, 2u);
  EXPECT_GT(sys.stats().keyframes, keyframes_before_localization);
  sys.waitForLocalMapping();  // returns at once
  sys.waitForLoopClosing();

  sys.reset();
  EXPECT_EQ(sys.stats().keyframes, 0u);
  sim::SynthFrame f = gen.frame(0);
  EXPECT_EQ(sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp + 100, {}).state, slam::TrackingState::Ok);
  EXPECT_EQ(sys.stats().keyframes, 1u);
  sys.shutdown();
  sys.shutdown();
  EXPECT_NE(sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp + 101, {}).state, slam::TrackingState::Ok);
}
