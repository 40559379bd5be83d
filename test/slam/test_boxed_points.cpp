// Tracking.boxedPointsStaticOnly: a keypoint screened static inside a person box gives a new
// keyframe of a map past its young frames a map point only when the frame-to-frame test found
// it static-consistent. Tracking.movedPointsWithheld: a keypoint that test saw move gives none,
// boxed or not. A synthetic static_xyz run is tracked from feature frames whose right half is
// marked as boxed (or not), with the motion test saying "moved" or "static" there; sequential
// mode, so the runs are deterministic.
#include "yolo_slam/common/config.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"
#include "support/static_scene.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

namespace {

constexpr int kFrames = 90;

enum class Marking { None, BoxedMoved, BoxedStatic, Moved };

struct Outcome {
  size_t withheld = 0;    // SystemStats::boxed_points_withheld
  size_t map_points = 0;
};

// Tracks the first `frames` frames of static_xyz, the right half of each marked as `marking` says.
Outcome run(Marking marking, bool rule_on, int frames = kFrames, bool moved_rule_on = false) {
  sim::SequenceGenerator gen(test_support::staticXyz(frames, 3));
  slam::SystemOptions opt = test_support::plainSequentialOptions();
  opt.slam.tracking.boxed_points_static_only = rule_on;
  opt.slam.tracking.moved_points_withheld = moved_rule_on;
  slam::System sys(gen.camera(), opt, nullptr);
  const features::OrbExtractor orb{features::OrbOptions::load(Config())};
  for (int i = 0; i < frames; ++i) {
    const sim::SynthFrame s = gen.frame(i);
    features::FeatureFrame f = features::buildFeatureFrame(orb, gen.camera(), s.bgr, s.depth, s.rgb_stamp);
    if (marking != Marking::None) {
      f.boxed.assign(f.size(), 0);
      f.motion.assign(f.size(), -1);
      for (size_t k = 0; k < f.size(); ++k) {
        if (f.keypoints[k].pt.x < f.width / 2) continue;
        f.boxed[k] = marking == Marking::Moved ? 0 : 1;
        f.motion[k] = marking == Marking::BoxedStatic ? 1 : 0;
      }
    }
    EXPECT_EQ(sys.trackFeatures(f).state, slam::TrackingState::Ok) << "frame " << i;
  }
  const slam::SystemStats st = sys.stats();
  return {st.boxed_points_withheld, st.map_points};
}

}  // namespace

TEST(SlamBoxedPoints, BoxedKeypointsThatMovedMakeNoKeyFramePoints) {
  EXPECT_TRUE(slam::TrackingOptions{}.boxed_points_static_only);
  const Outcome moved = run(Marking::BoxedMoved, true);
  std::printf("right half boxed and moved: %zu keyframe points withheld, %zu map points\n", moved.withheld,
              moved.map_points);
  EXPECT_GT(moved.withheld, 100u);
  // A young map (Tracking.youngMapFrames after its initialisation) keeps every point.
  const int young = slam::TrackingOptions{}.young_map_frames;
  EXPECT_EQ(run(Marking::BoxedMoved, true, young).withheld, 0u);
}

// Static-consistent boxed keypoints, or the rule off: the run is the unmarked one.
TEST(SlamBoxedPoints, StaticConsistentOrRuleOffMapAsUnmarked) {
  const Outcome plain = run(Marking::None, true);
  const Outcome static_boxed = run(Marking::BoxedStatic, true);
  const Outcome off = run(Marking::BoxedMoved, false);
  EXPECT_EQ(plain.withheld, 0u);
  EXPECT_EQ(static_boxed.withheld, 0u);
  EXPECT_EQ(off.withheld, 0u);
  EXPECT_EQ(static_boxed.map_points, plain.map_points);
  EXPECT_EQ(off.map_points, plain.map_points);
}

// A keypoint seen moving outside every box: withheld with movedPointsWithheld (the default), not
// without it; the young map keeps every point.
TEST(SlamBoxedPoints, MovedKeypointsMakeNoKeyFramePoints) {
  EXPECT_TRUE(slam::TrackingOptions{}.moved_points_withheld);
  const Outcome plain = run(Marking::None, true);
  const Outcome moved = run(Marking::Moved, true, kFrames, true);
  std::printf("right half moved: %zu keyframe points withheld, %zu map points (unmarked: %zu)\n", moved.withheld,
              moved.map_points, plain.map_points);
  EXPECT_GT(moved.withheld, 100u);
  EXPECT_LT(moved.map_points, plain.map_points);
  const Outcome off = run(Marking::Moved, true, kFrames, false);
  EXPECT_EQ(off.withheld, 0u);
  EXPECT_EQ(off.map_points, plain.map_points);
  const int young = slam::TrackingOptions{}.young_map_frames;
  EXPECT_EQ(run(Marking::Moved, true, young, true).withheld, 0u);
}
