#pragma once
// The fixture of the SLAM tests that drive tracking by hand on the synthetic static_xyz preset:
// the sequence, options with screening and loop closing off in the deterministic sequential
// mode, and the blank frame (no features, no depth) that makes tracking lost.
#include "yolo_slam/common/config.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"

#include <opencv2/core.hpp>

namespace yolo_slam {
namespace test_support {

inline sim::SynthOptions staticXyz(int frames, unsigned seed) {
  sim::SynthOptions so;
  so.preset = "static_xyz";
  so.frames = frames;
  so.seed = seed;
  return so;
}

inline slam::SystemOptions plainSequentialOptions() {
  slam::SystemOptions opt = slam::SystemOptions::load(Config());
  opt.screening.mode = screening::DynamicMode::Off;
  opt.slam.loop.enabled = false;
  opt.sequential = true;
  return opt;
}

struct BlankFrame {
  cv::Mat bgr, depth;
};

inline BlankFrame blankFrame(const sim::SynthFrame& like) {
  return {cv::Mat(like.bgr.size(), like.bgr.type(), cv::Scalar::all(0)), cv::Mat(like.depth.size(), CV_32F, cv::Scalar(0))};
}

}  // namespace test_support
}  // namespace yolo_slam
