// Relocalisation end to end: a synthetic static_xyz run is interrupted by blank frames (tracking
// lost), then resumes at a frame from early in the sequence (a jump of the camera back to a
// mapped place). Tracking must recover through the BoW relocalisation (counted in the stats)
// with a pose error of a few centimetres, and keep tracking afterwards.
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

namespace {
std::shared_ptr<const vocabulary::Vocabulary> shippedVocabulary() {
  return vocabulary::Vocabulary::load(packageDir() + "/vocab/yolo_slam_orb_k10_L4.vocab");
}
}  // namespace

TEST(SlamRelocalization, RecoversAfterBlankFramesAndJumpBack) {
  sim::SynthOptions so;
  so.preset = "static_xyz";
  so.frames = 100;
  so.seed = 5;
  sim::SequenceGenerator gen(so);
  ASSERT_EQ(gen.size(), 100u);

  slam::SystemOptions opt = slam::SystemOptions::load(Config());
  opt.screening.mode = screening::DynamicMode::Off;
  opt.slam.loop.enabled = false;
  slam::System sys(gen.camera(), opt, shippedVocabulary());

  const Pose T_w0 = gen.frame(0).T_wc;  // the map's world frame is the first camera
  double stamp = 0;
  for (size_t i = 0; i < 100; ++i) {
    sim::SynthFrame f = gen.frame(i);
    stamp = f.rgb_stamp;
    ASSERT_EQ(sys.trackRgbd(f.bgr, f.depth, stamp, {}).state, slam::TrackingState::Ok) << "frame " << i;
    if (i % 10 == 0) sys.waitForLocalMapping();
  }
  sys.waitForLocalMapping();

  // Blank frames: no features, no depth -> lost.
  sim::SynthFrame f0 = gen.frame(0);
  cv::Mat black(f0.bgr.size(), f0.bgr.type(), cv::Scalar::all(0));
  cv::Mat no_depth(f0.depth.size(), CV_32F, cv::Scalar(0));
  for (int k = 0; k < 5; ++k) {
    stamp += 1.0 / 30;
    EXPECT_NE(sys.trackRgbd(black, no_depth, stamp, {}).state, slam::TrackingState::Ok);
  }
  EXPECT_EQ(sys.state(), slam::TrackingState::Lost);
  const size_t relocs_before = sys.stats().relocalizations;

  // Back to frames 10..30 (mapped at the start of the run).
  int tracked_after = 0;
  double first_err = -1;
  for (size_t i = 10; i <= 30; ++i) {
    sim::SynthFrame f = gen.frame(i);
    stamp += 1.0 / 30;
    slam::TrackResult r = sys.trackRgbd(f.bgr, f.depth, stamp, {});
    if (r.state != slam::TrackingState::Ok) continue;
    ++tracked_after;
    const Pose gt = T_w0.inverse() * f.T_wc;
    const double err = (gt.translation() - r.T_wc.translation()).norm();
    if (first_err < 0) first_err = err;
    EXPECT_LT(err, 0.03) << "frame " << i;
  }
  std::printf("relocalised: first pose error %.4f m, %d/21 frames tracked after the jump\n", first_err,
              tracked_after);
  EXPECT_GE(first_err, 0.0);
  EXPECT_GE(tracked_after, 20);
  EXPECT_GE(sys.stats().relocalizations, relocs_before + 1);
}
