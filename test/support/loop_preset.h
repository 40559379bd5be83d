#pragma once
// The loop-closing fixture shared by the SLAM tests: the shipped vocabulary and the "loop"
// preset at 5 fps (200 frames, the preset's 40 s), whose camera returns to its start.
#include "yolo_slam/common/paths.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <memory>

namespace yolo_slam {
namespace test_support {

inline std::shared_ptr<const vocabulary::Vocabulary> shippedVocabulary() {
  return vocabulary::Vocabulary::load(packageDir() + "/vocab/yolo_slam_orb_k10_L4.vocab");
}

inline sim::SynthOptions loopPreset() {
  sim::SynthOptions so;
  so.preset = "loop";
  so.fps = 5.0;
  so.frames = 200;
  so.seed = 2;
  return so;
}

}  // namespace test_support
}  // namespace yolo_slam
