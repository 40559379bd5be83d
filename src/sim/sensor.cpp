#include "yolo_slam/sim/sensor.h"

#include "yolo_slam/common/error.h"

#include <opencv2/imgproc.hpp>

#include <cmath>

namespace yolo_slam {
namespace sim {

SensorOptions SensorOptions::load(const Config& cfg) {
  SensorOptions o;
  o.min_depth = cfg.getDouble("Synth.minDepth", o.min_depth);
  o.max_depth = cfg.getDouble("Synth.maxDepth", o.max_depth);
  o.sigma_a = cfg.getDouble("Synth.depthNoiseA", o.sigma_a);
  o.sigma_b = cfg.getDouble("Synth.depthNoiseB", o.sigma_b);
  o.hole_rate = cfg.getDouble("Synth.holeRate", o.hole_rate);
  o.image_noise = cfg.getDouble("Synth.imageNoise", o.image_noise);
  o.motion_blur = cfg.getBool("Synth.motionBlur", o.motion_blur);
  o.exposure = cfg.getDouble("Synth.exposure", o.exposure);
  o.noise = cfg.getBool("Synth.noise", o.noise);
  if (o.min_depth < 0 || o.max_depth <= o.min_depth)
    throw Error(cfg.path() + ": Synth.minDepth/Synth.maxDepth must satisfy 0 <= min < max");
  if (o.sigma_a < 0 || o.sigma_b < 0 || o.hole_rate < 0 || o.image_noise < 0 || o.exposure < 0 ||
      o.exposure > 1)
    throw Error(cfg.path() + ": Synth.depthNoiseA/B, holeRate, imageNoise must be >= 0 and "
                "Synth.exposure in [0, 1]");
  return o;
}

cv::Mat applyDepthModel(const cv::Mat& exact, const SensorOptions& opt, cv::RNG& rng) {
  CV_Assert(exact.type() == CV_32F);
  const int W = exact.cols, H = exact.rows;
  cv::Mat out = exact.clone();
  if (!opt.noise) {
    out.setTo(0, (exact > opt.max_depth) | (exact < opt.min_depth));
    return out;
  }
  cv::Mat gauss(H, W, CV_32F);
  rng.fill(gauss, cv::RNG::NORMAL, 0.0, 1.0);
  const double fb = opt.disparity_fb, q = opt.subpixel;
  for (int y = 0; y < H; ++y) {
    const float* e = exact.ptr<float>(y);
    const float* g = gauss.ptr<float>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < W; ++x) {
      double z = e[x];
      if (z <= 0) { o[x] = 0; continue; }
      // Depth edges: the correlation window straddles two surfaces and gives no reading.
      bool edge = false;
      const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4 && !edge; ++k) {
        if (nx[k] < 0 || ny[k] < 0 || nx[k] >= W || ny[k] >= H) continue;
        double zn = exact.ptr<float>(ny[k])[nx[k]];
        edge = zn <= 0 || std::abs(zn - z) > opt.edge_jump * z;
      }
      if (edge) { o[x] = 0; continue; }
      double sigma = opt.sigma_a + opt.sigma_b * (z - 0.4) * (z - 0.4);
      double zn = z + sigma * g[x];
      double d = std::round(fb / zn * q) / q;  // disparity in 1/q pixel steps
      double zq = d > 0 ? fb / d : 0;
      o[x] = (zq < opt.min_depth || zq > opt.max_depth) ? 0.f : (float)zq;
    }
    // Projector shadow: left of a near surface, the far background the camera sees is not
    // lit by the projector (offset to the right) over the disparity difference.
    for (int x = 1; x < W; ++x) {
      double zl = e[x - 1], zr = e[x];
      if (zl <= 0 || zr <= 0 || zl - zr < opt.edge_jump * zr) continue;
      int w = (int)std::round(fb * (1.0 / zr - 1.0 / zl) * 0.5);
      for (int k = std::max(0, x - w); k < x; ++k)
        if (e[k] > zr + opt.edge_jump * zr) o[k] = 0;
    }
  }
  // Small random holes (specular or dark spots).
  int holes = (int)std::round(opt.hole_rate * rng.uniform(0.5, 1.5));
  for (int i = 0; i < holes; ++i) {
    cv::Point c(rng.uniform(0, W), rng.uniform(0, H));
    cv::Size ax(rng.uniform(1, 5), rng.uniform(1, 5));
    cv::ellipse(out, c, ax, rng.uniform(0.0, 180.0), 0, 360, cv::Scalar(0), cv::FILLED);
  }
  return out;
}

void applyImageNoise(cv::Mat& bgr, double sigma, cv::RNG& rng) {
  if (sigma <= 0) return;
  cv::Mat n(bgr.size(), CV_16SC3);
  rng.fill(n, cv::RNG::NORMAL, 0.0, sigma);
  cv::Mat tmp;
  bgr.convertTo(tmp, CV_16SC3);
  tmp += n;
  tmp.convertTo(bgr, CV_8UC3);  // saturating
}

void applyMotionBlur(cv::Mat& bgr, cv::Point2f shift) {
  double len = std::hypot(shift.x, shift.y);
  if (len < 1.0) return;
  int k = (int)std::ceil(len) | 1;
  cv::Mat kernel = cv::Mat::zeros(k, k, CV_32F);
  cv::Point2f c(k / 2.f, k / 2.f);
  cv::line(kernel, c - shift * 0.5f, c + shift * 0.5f, cv::Scalar(1.0), 1, cv::LINE_AA);
  double s = cv::sum(kernel)[0];
  if (s <= 0) return;
  kernel /= s;
  cv::filter2D(bgr, bgr, -1, kernel, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
}

}  // namespace sim
}  // namespace yolo_slam
