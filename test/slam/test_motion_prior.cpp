// The motion prior's default sigmas (Tracking.motionPrior, Tracking.motionPriorDeg) against the
// real camera: how far the real fr3_walking_xyz camera (its complete ground truth in ../shared)
// moves from the constant-velocity prediction from one frame to the next, measured as Tracking
// measures it (prediction = last motion applied to the last pose; deviation divided by the frames
// since the last one). Both sigmas sit near the same percentile of that deviation, so that where a
// far wall leaves a sideways shift and a turn indistinguishable, the prior prefers neither.
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/io/trajectory.h"
#include "yolo_slam/sim/camera_path.h"
#include "yolo_slam/slam/motion_model.h"
#include "yolo_slam/slam/options.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace yolo_slam;

namespace {

constexpr double kCameraFps = 30.0;  // TUM's nominal rate, Camera.fps of config/TUM3.yaml
constexpr double kPercentile = 0.95;

const std::string kTum = "data/tum/rgbd_dataset_freiburg3_walking_xyz";

// Stamps of every frame of the sequence (first column of its full association list).
std::vector<double> frameStamps() {
  std::ifstream in(joinPath(joinPath(sharedDir(), kTum), "full_associations/associations_all_frames.txt"));
  std::vector<double> stamps;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t;
    if (fields >> t) stamps.push_back(t);
  }
  return stamps;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * (v.size() - 1))];
}

struct Deviations {
  std::vector<double> centre_m, rotation_deg;
};

// Deviation of the real camera from the prediction one frame ahead at the mean velocity of the
// last `steps` steps (slam/motion_model.h; 1: the last step alone).
Deviations realDeviations(int steps) {
  const Trajectory gt = io::readTrajectory(joinPath(joinPath(sharedDir(), kTum), "groundtruth.txt"));
  const sim::CameraPath path = sim::CameraPath::replay(gt, gt.front().T_wc, "fr3_walking_xyz");
  const std::vector<double> stamps = frameStamps();
  const auto Tcw = [&](size_t k) { return Pose(path.at(stamps[k] - gt.front().stamp).inverse()); };
  Deviations d;
  for (size_t k = static_cast<size_t>(steps) + 1; k < stamps.size(); ++k) {
    slam::MotionHistory history;
    for (size_t j = k - 1 - static_cast<size_t>(steps); j < k; ++j) history.push(Tcw(j), static_cast<size_t>(steps) + 1);
    const Pose predicted = *history.meanStep(steps) * Tcw(k - 1);
    const Pose Twc2 = Tcw(k).inverse();
    const double gap = std::max(1.0, (stamps[k] - stamps[k - 1]) * kCameraFps);
    const Pose error = predicted * Twc2;
    d.centre_m.push_back((predicted.inverse().translation() - Twc2.translation()).norm() / gap);
    d.rotation_deg.push_back(Eigen::AngleAxisd(error.linear()).angle() * 180.0 / M_PI / gap);
  }
  return d;
}

}  // namespace

TEST(MotionPrior, DefaultSigmasSitAtTheSamePercentileOfARealCamerasMotion) {
  const slam::TrackingOptions opt;
  const Deviations d = realDeviations(opt.motion_prior_frames);
  ASSERT_GT(d.centre_m.size(), 800u) << "the real sequence's frame list in " << sharedDir();
  const double centre = percentile(d.centre_m, kPercentile);
  const double rotation = percentile(d.rotation_deg, kPercentile);
  std::printf("real camera, %.0fth percentile per frame, mean velocity of %d steps: centre %.2f mm, "
              "rotation %.3f deg; defaults %.2f mm, %.3f deg\n",
              100 * kPercentile, opt.motion_prior_frames, 1000 * centre, rotation, 1000 * opt.motion_prior,
              opt.motion_prior_deg);
  // Within a factor of 1.5 of the percentile each: 2 cm with 1 degree (the prior of before,
  // which let a far wall's ambiguity turn a sideways walk into a turn) fails.
  constexpr double kFactor = 1.5;
  EXPECT_LT(opt.motion_prior, kFactor * centre);
  EXPECT_GT(opt.motion_prior, centre / kFactor);
  EXPECT_LT(opt.motion_prior_deg, kFactor * rotation);
  EXPECT_GT(opt.motion_prior_deg, rotation / kFactor);
}

// The mean velocity of a few steps predicts the real camera about as well as the last step alone:
// the prior's sigmas need no change with it.
TEST(MotionPrior, MeanVelocityPredictsARealCameraAsWellAsTheLastStep) {
  constexpr int kMeanSteps = 4;  // Tracking.motionPriorFrames as measured in BENCHMARKS.md, "Session 43"
  const Deviations last = realDeviations(1), mean = realDeviations(kMeanSteps);
  ASSERT_GT(last.centre_m.size(), 800u) << "the real sequence's frame list in " << sharedDir();
  const double c1 = percentile(last.centre_m, kPercentile), cn = percentile(mean.centre_m, kPercentile);
  const double r1 = percentile(last.rotation_deg, kPercentile), rn = percentile(mean.rotation_deg, kPercentile);
  std::printf("95th percentile, last step / mean of %d: centre %.2f / %.2f mm, rotation %.3f / %.3f deg\n",
              kMeanSteps, 1000 * c1, 1000 * cn, r1, rn);
  constexpr double kWorseAtMost = 1.25;
  EXPECT_LT(cn, kWorseAtMost * c1);
  EXPECT_LT(rn, kWorseAtMost * r1);
}
