#include "yolo_slam/mapping/static_mask.h"

#include "yolo_slam/common/error.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace yolo_slam {
namespace mapping {

namespace {

// The screener seeds box k's RANSAC with seed + 7919 k; the mask does the same.
constexpr unsigned kBoxSeedStride = 7919u;
constexpr uint8_t kPerson = 255;

bool hasDepth(float d) { return d > 0 && std::isfinite(d); }

cv::Rect pixelRect(const cv::Rect2f& r, const cv::Size& size) {
  const cv::Rect whole(0, 0, size.width, size.height);
  const int x0 = static_cast<int>(std::floor(r.x)), y0 = static_cast<int>(std::floor(r.y));
  const int x1 = static_cast<int>(std::ceil(r.x + r.width)), y1 = static_cast<int>(std::ceil(r.y + r.height));
  return cv::Rect(x0, y0, x1 - x0, y1 - y0) & whole;
}

// Depths sampled every `stride` pixels of the region: what the screener's depth model sees of
// a box (it sees keypoints; a regular sample stands in for them).
struct Samples {
  std::vector<float> depths;
  std::vector<cv::Point> px;
};

Samples sampleDepths(const cv::Mat& depth, const cv::Rect& roi, int stride) {
  Samples s;
  for (int v = roi.y + stride / 2; v < roi.br().y; v += stride) {
    const float* row = depth.ptr<float>(v);
    for (int u = roi.x + stride / 2; u < roi.br().x; u += stride) {
      if (!hasDepth(row[u])) continue;
      s.depths.push_back(row[u]);
      s.px.emplace_back(u, v);
    }
  }
  return s;
}

// The samples the screener's variant calls the person.
std::vector<int> personSamples(const screening::Screener& screener, const Samples& s, unsigned box) {
  const screening::ScreeningOptions& o = screener.options();
  if (o.variant == screening::ScreeningVariant::Nearest) return screener.nearestCluster(s.depths);
  return screener.depthRansac(s.depths, o.seed + kBoxSeedStride * box).members;
}

// Flood fill from the seeds over 4-connected pixels of roi whose depth lies in [lo, hi] and
// differs from the neighbour it is reached from by less than `step` (connected depth: the
// person, not the background at the same depth elsewhere in the box).
void growOverDepth(const cv::Mat& depth, const cv::Rect& roi, const std::vector<cv::Point>& seeds,
                   float lo, float hi, float step, cv::Mat& person) {
  std::vector<cv::Point> queue;
  for (const cv::Point& p : seeds) {
    if (person.at<uint8_t>(p) == kPerson) continue;
    person.at<uint8_t>(p) = kPerson;
    queue.push_back(p);
  }
  static const cv::Point kSteps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  for (size_t q = 0; q < queue.size(); ++q) {
    const cv::Point p = queue[q];
    const float d = depth.at<float>(p);
    for (const cv::Point& s : kSteps) {
      const cv::Point n = p + s;
      if (!roi.contains(n) || person.at<uint8_t>(n) == kPerson) continue;
      const float dn = depth.at<float>(n);
      if (!hasDepth(dn) || dn < lo || dn > hi || std::abs(dn - d) >= step) continue;
      person.at<uint8_t>(n) = kPerson;
      queue.push_back(n);
    }
  }
}

// One box's person pixels (detect+geometry): the depth model's cluster, grown over connected
// depth within the cluster's depth range widened by the screener's grow depth.
void markPerson(const cv::Mat& depth, const cv::Rect& roi, const screening::Screener& screener,
                int stride, unsigned box, cv::Mat& person) {
  const Samples s = sampleDepths(depth, roi, stride);
  const std::vector<int> members = personSamples(screener, s, box);
  if (members.empty()) return;
  float lo = s.depths[members[0]], hi = lo;
  std::vector<cv::Point> seeds;
  for (int m : members) {
    lo = std::min(lo, s.depths[m]);
    hi = std::max(hi, s.depths[m]);
    seeds.push_back(s.px[m]);
  }
  const float grow = static_cast<float>(screener.options().grow_depth_m);
  growOverDepth(depth, roi, seeds, lo - grow, hi + grow, grow, person);
}

}  // namespace

cv::Mat staticMask(const cv::Mat& depth_m, const detection::Boxes& boxes,
                   const screening::Screener& screener, const StaticMaskOptions& options) {
  if (depth_m.type() != CV_32FC1)
    throw Error("dense map: the static mask needs a CV_32FC1 depth image in metres");
  using screening::DynamicMode;
  const screening::ScreeningOptions& o = screener.options();
  cv::Mat person(depth_m.size(), CV_8UC1, cv::Scalar(0));
  if (o.mode == DynamicMode::Detect || o.mode == DynamicMode::DetectGeometry) {
    for (size_t k = 0; k < boxes.size(); ++k) {
      const cv::Rect roi = pixelRect(screening::dilate(boxes[k].rect, o.box_dilation), depth_m.size());
      if (roi.empty()) continue;
      if (o.mode == DynamicMode::Detect)
        person(roi).setTo(kPerson);
      else
        markPerson(depth_m, roi, screener, options.sample_stride_px, static_cast<unsigned>(k), person);
    }
  }
  if (options.margin_px > 0) {
    const int d = 2 * options.margin_px + 1;
    cv::dilate(person, person, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(d, d)));
  }
  cv::Mat mask;
  cv::bitwise_not(person, mask);
  return mask;
}

}  // namespace mapping
}  // namespace yolo_slam
