// Young-map reset (Tracking.youngMapFrames, youngLostResetFrames): a map lost within
// youngMapFrames frames of its initialisation is reset after youngLostResetFrames lost frames
// and a new one starts at the last good pose; an older map waits for relocalisation (and the
// lostResetFrames / lostResetMaxKeyFrames rule). Blank frames (no features, no depth) make
// tracking lost on a synthetic static_xyz sequence; sequential mode, so the runs are
// deterministic.
#include "yolo_slam/common/config.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"
#include "support/static_scene.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

namespace {

struct Outcome {
  size_t resets = 0;
  int tracked_after = 0;  // real frames tracked after the blank ones
  size_t poses = 0;       // trajectory poses at the end
};

// Tracks `before` frames, then `blank` blank frames, then the next 10 real frames.
Outcome runWithBlanks(int before, int blank, int young_lost_reset_frames) {
  sim::SequenceGenerator gen(test_support::staticXyz(before + 10, 5));
  slam::SystemOptions opt = test_support::plainSequentialOptions();
  opt.slam.tracking.young_map_frames = 30;
  opt.slam.tracking.young_lost_reset_frames = young_lost_reset_frames;
  slam::System sys(gen.camera(), opt, nullptr);  // no vocabulary: no BoW relocalisation
  double stamp = 0;
  for (int i = 0; i < before; ++i) {
    sim::SynthFrame f = gen.frame(i);
    stamp = f.rgb_stamp;
    EXPECT_EQ(sys.trackRgbd(f.bgr, f.depth, stamp, {}).state, slam::TrackingState::Ok) << "frame " << i;
  }
  const sim::SynthFrame f0 = gen.frame(0);
  const test_support::BlankFrame blank_frame = test_support::blankFrame(f0);
  for (int k = 0; k < blank; ++k) {
    stamp += 1.0 / 30;
    sys.trackRgbd(blank_frame.bgr, blank_frame.depth, stamp, {});
  }
  Outcome out;
  for (int i = before; i < before + 10; ++i) {
    sim::SynthFrame f = gen.frame(i);
    stamp += 1.0 / 30;
    out.tracked_after += sys.trackRgbd(f.bgr, f.depth, stamp, {}).state == slam::TrackingState::Ok;
  }
  out.resets = sys.stats().resets;
  out.poses = sys.cameraTrajectory().size();
  return out;
}

}  // namespace

TEST(SlamYoungMapReset, YoungMapLostIsResetAndTrackingGoesOn) {
  const Outcome o = runWithBlanks(10, 4, 3);  // reset at the third blank frame
  EXPECT_EQ(o.resets, 1u);
  // The new map starts on the first real frame: everything after the blanks is tracked, and
  // the poses of the first map stay in the trajectory.
  EXPECT_EQ(o.tracked_after, 10);
  EXPECT_EQ(o.poses, 20u);
}

TEST(SlamYoungMapReset, OlderMapsAndShortLossesAreKept) {
  EXPECT_EQ(slam::TrackingOptions{}.young_lost_reset_frames, 10);
  EXPECT_EQ(runWithBlanks(10, 4, 0).resets, 0u);   // the rule off
  EXPECT_EQ(runWithBlanks(40, 4, 3).resets, 0u);   // lost 40 frames after initialisation: not young
  EXPECT_EQ(runWithBlanks(10, 2, 3).resets, 0u);   // fewer lost frames than the rule waits for
}
