#pragma once
// Kinect-like sensor effects applied to exact renderings: structured-light depth (disparity
// quantisation, noise growing with the square of depth, range limits, projector shadows and
// missing readings along depth edges, small random holes), mild image noise, motion blur.
#include "yolo_slam/common/config.h"

#include <opencv2/core.hpp>

namespace yolo_slam {
namespace sim {

struct SensorOptions {
  double min_depth = 0.4;        // m: no reading nearer
  double max_depth = 4.5;        // m: no reading farther
  double disparity_fb = 43.5;    // px*m: IR focal length x projector baseline (580 px x 7.5 cm)
  double subpixel = 8;           // disparity steps per pixel (Kinect: 1/8 px)
  double sigma_a = 0.0012;       // depth noise sigma = a + b (z - 0.4)^2 (Nguyen et al. 2012)
  double sigma_b = 0.0019;
  double edge_jump = 0.05;       // relative depth jump between neighbours that loses the reading
  double hole_rate = 20;         // mean number of small random holes per frame
  double image_noise = 2.0;      // sigma of additive Gaussian noise on 8-bit colour
  bool motion_blur = false;      // blur colour along the image motion during the exposure
  double exposure = 0.5;         // exposure time as a fraction of the frame interval
  bool noise = true;             // false: exact depth and colour (for geometry checks)

  // Reads Synth.* keys (Synth.maxDepth, Synth.minDepth, Synth.depthNoiseA/B, Synth.holeRate,
  // Synth.imageNoise, Synth.motionBlur, Synth.exposure, Synth.noise).
  static SensorOptions load(const Config& cfg);
};

// Sensor depth (CV_32F metres, 0 = no reading) from exact depth (CV_32F, 0 = nothing hit).
cv::Mat applyDepthModel(const cv::Mat& exact, const SensorOptions& opt, cv::RNG& rng);

// Additive Gaussian noise on a CV_8UC3 image, in place.
void applyImageNoise(cv::Mat& bgr, double sigma, cv::RNG& rng);

// Linear motion blur along `shift` (pixels travelled during the exposure), in place.
void applyMotionBlur(cv::Mat& bgr, cv::Point2f shift);

}  // namespace sim
}  // namespace yolo_slam
