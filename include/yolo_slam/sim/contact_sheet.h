#pragma once
// A contact sheet of synthetic sequences: one row per preset holding, for each chosen frame,
// rgb (with the ground-truth boxes), colourised sensor depth (black = no reading) and the mask.
#include "yolo_slam/sim/generator.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace yolo_slam {
namespace sim {

// Rows for `frames` of each preset (indices into the preset's full length), tiles scaled to
// `tile_width` pixels wide. `base` supplies seed, textures and sensor settings.
cv::Mat contactSheet(const SynthOptions& base, const std::vector<std::string>& preset_names,
                     const std::vector<int>& frames, int tile_width = 256);

// Colourised depth: turbo-like map over [0, max_m], black where there is no reading.
cv::Mat colouriseDepth(const cv::Mat& depth_m, double max_m = 4.5);

}  // namespace sim
}  // namespace yolo_slam
