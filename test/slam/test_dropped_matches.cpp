// Tracking.droppedMapMatches: in localization mode, keypoints the screening dropped (here a
// pretend person box over the middle of the image, with nobody in it) that the frame-to-frame
// test did not see move match the loaded map's points and count as static again; never in SLAM
// mode, never when the test saw them move, never with the option at 0. A synthetic static_xyz
// run is mapped, then tracked on; sequential mode, so the runs are deterministic.
#include "yolo_slam/common/config.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"
#include "support/static_scene.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

namespace {

constexpr int kMappedFrames = 30;
constexpr int kTrackedFrames = 10;
// The pretend person box: a third of the image, in its middle.
const cv::Rect2f kBox(213.f, 160.f, 213.f, 160.f);

struct Case {
  int dropped_map_matches = 3;
  bool localization = true;
  int8_t motion = 1;  // the frame-to-frame verdict of every keypoint: 1 static-consistent, 0 moved
};

struct Outcome {
  size_t matched = 0;
  size_t tracked = 0;
};

// Every keypoint inside kBox dropped, as the screening drops the background of a person's box.
void dropInBox(features::FeatureFrame& f, int8_t motion) {
  const size_t n = f.keypoints.size();
  f.dynamic.assign(n, 0);
  f.motion.assign(n, motion);
  for (size_t i = 0; i < n; ++i) f.dynamic[i] = kBox.contains(f.keypoints[i].pt) ? 1 : 0;
}

Outcome mapThenTrack(const Case& c) {
  sim::SequenceGenerator gen(test_support::staticXyz(kMappedFrames + kTrackedFrames, 4));
  slam::SystemOptions opt = test_support::plainSequentialOptions();
  opt.slam.tracking.dropped_map_matches = c.dropped_map_matches;
  slam::System sys(gen.camera(), opt, nullptr);
  const features::OrbExtractor orb{features::OrbOptions::load(Config())};
  Outcome out;
  for (int i = 0; i < kMappedFrames + kTrackedFrames; ++i) {
    if (i == kMappedFrames) sys.setLocalizationOnly(c.localization);
    const sim::SynthFrame s = gen.frame(i);
    features::FeatureFrame f = features::buildFeatureFrame(orb, gen.camera(), s.bgr, s.depth, s.rgb_stamp);
    if (i >= kMappedFrames) dropInBox(f, c.motion);
    const bool ok = sys.trackFeatures(f).state == slam::TrackingState::Ok;
    if (i >= kMappedFrames) out.tracked += ok ? 1 : 0;
  }
  out.matched = sys.stats().dropped_map_matches;
  return out;
}

}  // namespace

TEST(SlamDroppedMatches, LocalizationMatchesTheDroppedBackgroundToTheMap) {
  EXPECT_EQ(slam::TrackingOptions{}.dropped_map_matches, 3);
  const Outcome o = mapThenTrack(Case{});
  EXPECT_EQ(o.tracked, static_cast<size_t>(kTrackedFrames));
  // The box is a ninth of the image; 53 of its keypoints a frame matched when this test was
  // written.
  EXPECT_GE(o.matched, static_cast<size_t>(kTrackedFrames * 20));
}

TEST(SlamDroppedMatches, NotInSlamModeNorWhenSeenMovingNorWhenOff) {
  Case slam_mode;
  slam_mode.localization = false;
  Case moved;
  moved.motion = 0;
  Case off;
  off.dropped_map_matches = 0;
  for (const Case& c : {slam_mode, moved, off}) {
    const Outcome o = mapThenTrack(c);
    EXPECT_EQ(o.tracked, static_cast<size_t>(kTrackedFrames));
    EXPECT_EQ(o.matched, 0u) << "localization " << c.localization << ", motion " << int(c.motion)
                             << ", droppedMapMatches " << c.dropped_map_matches;
  }
}
