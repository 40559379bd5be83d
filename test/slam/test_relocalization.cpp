// Relocalisation end to end: a synthetic static_xyz run is interrupted by blank frames (tracking
// lost), then resumes at a frame from early in the sequence (a jump of the camera back to a
// mapped place). Tracking must recover through the BoW relocalisation (counted in the stats)
// with a pose error of a few centimetres, and keep tracking afterwards.
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"
#include "yolo_slam/vocabulary/vocabulary.h"
#include "support/static_scene.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace yolo_slam;

namespace {
std::shared_ptr<const vocabulary::Vocabulary> shippedVocabulary() {
  return vocabulary::Vocabulary::load(packageDir() + "/vocab/yolo_slam_orb_k10_L4.vocab");
}

struct JumpBack {
  int tracked_after = 0;      // frames tracked of the 21 after the jump
  double first_err = -1;      // pose error of the first of them (m)
  double max_err = 0;         // the largest error of them (m)
  size_t relocalizations = 0; // relocalisations after the blank frames
};

// 100 frames of static_xyz, 5 blank frames (lost), then frames 10..30 again.
JumpBack runJumpBack(slam::SystemOptions opt) {
  sim::SequenceGenerator gen(test_support::staticXyz(100, 5));
  EXPECT_EQ(gen.size(), 100u);

  opt.screening.mode = screening::DynamicMode::Off;
  opt.slam.loop.enabled = false;
  slam::System sys(gen.camera(), opt, shippedVocabulary());

  const Pose T_w0 = gen.frame(0).T_wc;  // the map's world frame is the first camera
  double stamp = 0;
  for (size_t i = 0; i < 100; ++i) {
    sim::SynthFrame f = gen.frame(i);
    stamp = f.rgb_stamp;
    EXPECT_EQ(sys.trackRgbd(f.bgr, f.depth, stamp, {}).state, slam::TrackingState::Ok) << "frame " << i;
    if (i % 10 == 0) sys.waitForLocalMapping();
  }
  sys.waitForLocalMapping();

  // Blank frames: no features, no depth -> lost.
  sim::SynthFrame f0 = gen.frame(0);
  const test_support::BlankFrame blank = test_support::blankFrame(f0);
  for (int k = 0; k < 5; ++k) {
    stamp += 1.0 / 30;
    EXPECT_NE(sys.trackRgbd(blank.bgr, blank.depth, stamp, {}).state, slam::TrackingState::Ok);
  }
  EXPECT_EQ(sys.state(), slam::TrackingState::Lost);
  const size_t relocs_before = sys.stats().relocalizations;

  // Back to frames 10..30 (mapped at the start of the run).
  JumpBack out;
  for (size_t i = 10; i <= 30; ++i) {
    sim::SynthFrame f = gen.frame(i);
    stamp += 1.0 / 30;
    slam::TrackResult r = sys.trackRgbd(f.bgr, f.depth, stamp, {});
    if (r.state != slam::TrackingState::Ok) continue;
    ++out.tracked_after;
    const Pose gt = T_w0.inverse() * f.T_wc;
    const double err = (gt.translation() - r.T_wc.translation()).norm();
    if (out.first_err < 0) out.first_err = err;
    out.max_err = std::max(out.max_err, err);
  }
  out.relocalizations = sys.stats().relocalizations - relocs_before;
  return out;
}

// Tracks frames 0 .. frames-1 of gen (each must track), then `blanks` blank frames a frame apart;
// returns the last stamp.
double trackThenBlank(slam::System& sys, const sim::SequenceGenerator& gen, size_t frames, int blanks) {
  double stamp = 0;
  for (size_t i = 0; i < frames; ++i) {
    const sim::SynthFrame f = gen.frame(i);
    stamp = f.rgb_stamp;
    EXPECT_EQ(sys.trackRgbd(f.bgr, f.depth, stamp, {}).state, slam::TrackingState::Ok) << "frame " << i;
  }
  const test_support::BlankFrame blank = test_support::blankFrame(gen.frame(0));
  for (int k = 0; k < blanks; ++k) {
    stamp += 1.0 / 30;
    sys.trackRgbd(blank.bgr, blank.depth, stamp, {});
  }
  return stamp;
}

}  // namespace

TEST(SlamRelocalization, RecoversAfterBlankFramesAndJumpBack) {
  const JumpBack r = runJumpBack(slam::SystemOptions::load(Config()));
  std::printf("relocalised: first pose error %.4f m, %d/21 frames tracked after the jump\n", r.first_err,
              r.tracked_after);
  EXPECT_GE(r.first_err, 0.0);
  EXPECT_LT(r.max_err, 0.03);
  EXPECT_GE(r.tracked_after, 20);
  EXPECT_GE(r.relocalizations, 1u);
}

// Tracking.relocMinInliers holds for the frames right after a relocalisation (the relocalised
// frame among them), not before: set out of reach, the 100 frames before the loss track, and
// after the jump every frame relocalises and then fails its local-map step.
TEST(SlamRelocalization, FramesAfterRelocalisationNeedRelocMinInliers) {
  slam::SystemOptions opt = slam::SystemOptions::load(Config());
  ASSERT_EQ(opt.slam.tracking.reloc_min_inliers, 50);
  opt.slam.tracking.reloc_min_inliers = 100000;
  const JumpBack r = runJumpBack(opt);
  EXPECT_EQ(r.tracked_after, 0);
  EXPECT_GE(r.relocalizations, 10u);
}

namespace {

struct OnwardJump {
  slam::TrackingState state = slam::TrackingState::NotInitialized;  // of frame 190
  size_t relocalizations = 0, refused = 0;  // after the loss
  double err = -1;  // frame 190's pose error (m) when it was tracked
};

// The camera circles an empty room (static_xyz's room on the loop path); after a loss it jumps
// back to frame 10 (0.76 m from frame 199, a second later: relocalised there), then on to frame
// 190, 0.73 m from frame 10 and a wall 55 degrees further round that frame 10's keyframe does not
// see well, stamped `gap_s` after frame 10.
OnwardJump jumpBackThenOn(double gap_s, double reloc_max_speed) {
  sim::SynthOptions so = test_support::staticXyz(200, 5);
  so.trajectory = "loop";
  sim::SequenceGenerator gen(so);
  slam::SystemOptions opt = test_support::plainSequentialOptions();
  opt.slam.tracking.reloc_max_speed = reloc_max_speed;
  slam::System sys(gen.camera(), opt, shippedVocabulary());
  double stamp = trackThenBlank(sys, gen, gen.size(), 3);
  EXPECT_EQ(sys.state(), slam::TrackingState::Lost);
  const size_t relocs_before = sys.stats().relocalizations;
  stamp += 1.0;
  const sim::SynthFrame back = gen.frame(10);
  EXPECT_EQ(sys.trackRgbd(back.bgr, back.depth, stamp, {}).state, slam::TrackingState::Ok);
  const sim::SynthFrame on = gen.frame(190);
  const slam::TrackResult r = sys.trackRgbd(on.bgr, on.depth, stamp + gap_s, {});
  OnwardJump out;
  out.state = r.state;
  out.relocalizations = sys.stats().relocalizations - relocs_before;
  out.refused = sys.stats().relocalizations_refused;
  const Pose gt = gen.frame(0).T_wc.inverse() * on.T_wc;
  if (r.state == slam::TrackingState::Ok) out.err = (gt.translation() - r.T_wc.translation()).norm();
  return out;
}

}  // namespace

// The frame right after a relocalisation has no velocity: when its reference keyframe (the
// one it relocalised on) does not track it either, it relocalises at once. Frame 190 comes 0.6 s
// after frame 10, time enough for a camera to get there (Tracking.relocMaxSpeed 1.5 m/s).
TEST(SlamRelocalization, FrameAfterARelocalisationRelocalisesAtOnce) {
  const OnwardJump run = jumpBackThenOn(0.6, slam::TrackingOptions().reloc_max_speed);
  EXPECT_EQ(run.state, slam::TrackingState::Ok);
  EXPECT_EQ(run.relocalizations, 2u);
  EXPECT_EQ(run.refused, 0u);
  EXPECT_LT(run.err, 0.03);
}

// A frame a camera cannot have reached since the last tracked one (0.73 m in a frame's time) is
// not relocalised: a place recognised wrongly would move it as far. With the bound off
// (ORB-SLAM2) the same frame is relocalised.
TEST(SlamRelocalization, RelocalisationOutOfReachIsRefused) {
  const OnwardJump bounded = jumpBackThenOn(1.0 / 30, slam::TrackingOptions().reloc_max_speed);
  EXPECT_NE(bounded.state, slam::TrackingState::Ok);
  EXPECT_EQ(bounded.relocalizations, 1u);
  EXPECT_GE(bounded.refused, 1u);
  const OnwardJump unbounded = jumpBackThenOn(1.0 / 30, 0.0);
  EXPECT_EQ(unbounded.state, slam::TrackingState::Ok);
  EXPECT_EQ(unbounded.relocalizations, 2u);
  EXPECT_EQ(unbounded.refused, 0u);
  EXPECT_LT(unbounded.err, 0.03);
}

// A map reset forgets the relocalisations of the old map: Tracking.relocMinInliers out of reach
// makes every relocalisation in a young map fail its local-map step, the young map is reset,
// and the new map, started right after, tracks with the ordinary Tracking.minInliers.
TEST(SlamRelocalization, NewMapAfterResetIgnoresOldRelocalisation) {
  sim::SequenceGenerator gen(test_support::staticXyz(40, 5));
  slam::SystemOptions opt = test_support::plainSequentialOptions();
  opt.slam.tracking.young_map_frames = 30;
  opt.slam.tracking.young_lost_reset_frames = 3;
  opt.slam.tracking.reloc_min_inliers = 100000;
  slam::System sys(gen.camera(), opt, shippedVocabulary());
  double stamp = 0;
  for (size_t i = 0; i < 10; ++i) {
    const sim::SynthFrame f = gen.frame(i);
    stamp = f.rgb_stamp;
    ASSERT_EQ(sys.trackRgbd(f.bgr, f.depth, stamp, {}).state, slam::TrackingState::Ok) << "frame " << i;
  }
  const sim::SynthFrame f0 = gen.frame(0);
  const test_support::BlankFrame blank = test_support::blankFrame(f0);
  for (int k = 0; k < 2; ++k) {
    stamp += 1.0 / 30;
    sys.trackRgbd(blank.bgr, blank.depth, stamp, {});
  }
  int tracked_after = 0;
  for (size_t i = 2; i < 22; ++i) {  // back to frames mapped before the loss
    const sim::SynthFrame f = gen.frame(i);
    stamp += 1.0 / 30;
    tracked_after += sys.trackRgbd(f.bgr, f.depth, stamp, {}).state == slam::TrackingState::Ok;
  }
  const slam::SystemStats st = sys.stats();
  EXPECT_GE(st.relocalizations, 1u);
  EXPECT_EQ(st.resets, 1u);
  EXPECT_GE(tracked_after, 18);
}

// Lost while the camera moves on (people hid the room for a second): the last good pose is too
// far for the reference keyframe's optimisation to start from, and a strip of the room is all
// that shows again, too little for a relocalisation over the whole map (50 inliers). The
// keyframes near where tracking was lost relocalise it with fewer (Tracking::trackWhenLost):
// static_xyz tracked for 60 frames, 30 blank frames while the camera goes on, then frame 89
// with only its left 118 columns visible.
TEST(SlamRelocalization, LostWhileMovingRecoversNearTheLastKeyframesFromAStrip) {
  sim::SequenceGenerator gen(test_support::staticXyz(100, 5));
  slam::System sys(gen.camera(), test_support::plainSequentialOptions(), shippedVocabulary());
  double stamp = trackThenBlank(sys, gen, 60, 30);
  ASSERT_EQ(sys.state(), slam::TrackingState::Lost);
  const sim::SynthFrame f = gen.frame(89);
  constexpr int kStripWidth = 118;
  const cv::Rect hidden(kStripWidth, 0, f.bgr.cols - kStripWidth, f.bgr.rows);
  cv::Mat bgr = f.bgr.clone(), depth = f.depth.clone();
  bgr(hidden).setTo(cv::Scalar::all(0));
  depth(hidden).setTo(0);
  const size_t relocs_before = sys.stats().relocalizations;
  stamp += 1.0 / 30;
  const slam::TrackResult r = sys.trackRgbd(bgr, depth, stamp, {});
  ASSERT_EQ(r.state, slam::TrackingState::Ok);
  EXPECT_EQ(sys.stats().relocalizations - relocs_before, 1u);
  const Pose gt = gen.frame(0).T_wc.inverse() * f.T_wc;
  EXPECT_LT((gt.translation() - r.T_wc.translation()).norm(), 0.03);
}
