#include "yolo_slam/features/orb_extractor.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/option_checks.h"

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <future>
#include <numeric>
#include <random>

namespace yolo_slam {
namespace features {

// ------------------------------------------------------------------------------------------
// Options
// ------------------------------------------------------------------------------------------

namespace {

const OptionTable<OrbOptions>& orbFields() {
  using O = OrbOptions;
  static const OptionTable<O> table = {
      {"ORBextractor.nFeatures", &O::n_features, Range::atLeast(O::kMinFeatures)},
      {"ORBextractor.scaleFactor", &O::scale_factor, Range::openClosed(1, 4)},
      {"ORBextractor.nLevels", &O::n_levels, Range::closed(1, 32)},
      {"ORBextractor.iniThFAST", &O::ini_th_fast, Range::closed(1, 254)},
      {"ORBextractor.minThFAST", &O::min_th_fast, Range::closed(1, 254)},
      {"ORBextractor.dynamicBoostMax", &O::dynamic_boost_max, Range::closed(1, 4)},
      {"ORBextractor.threads", &O::threads, Range::closed(1, O::kMaxThreads)},
  };
  return table;
}

// The fallback threshold is the lower one.
void checkThresholds(const OrbOptions& o, const std::string& where) {
  if (o.min_th_fast > o.ini_th_fast)
    rejectOption(where, "ORBextractor.minThFAST",
                 "in [1, iniThFAST = " + std::to_string(o.ini_th_fast) + "]",
                 std::to_string(o.min_th_fast));
}

}  // namespace

void OrbOptions::validate(const std::string& where) const {
  checkOptions(*this, where, orbFields());
  checkThresholds(*this, where);
}

OrbOptions OrbOptions::load(const Config& cfg) {
  OrbOptions o;
  readOptions(cfg, o, orbFields());
  checkThresholds(o, configName(cfg));
  return o;
}

// ------------------------------------------------------------------------------------------
// BRIEF sampling pattern
// ------------------------------------------------------------------------------------------

const std::vector<cv::Point>& OrbExtractor::briefPattern() {
  // BRIEF "G II" sampling (Calonder et al. 2010): both points of a test drawn from an isotropic
  // Gaussian with sigma^2 = S^2/25 around the patch centre, S = 31. Points outside the circle of
  // radius 15 are redrawn so that any rotation of the pattern stays inside the 19 px border.
  // std::normal_distribution is implementation-defined, so Box-Muller on the raw (standardised)
  // mt19937 output keeps the pattern identical on every platform.
  static const std::vector<cv::Point> pattern = [] {
    std::mt19937 gen(0x0b51a7e5u);
    const double sigma = kPatchSize / 5.0;
    auto uniform = [&gen]() { return (static_cast<double>(gen()) + 0.5) / 4294967296.0; };
    auto samplePoint = [&]() {
      while (true) {
        double r = std::sqrt(-2.0 * std::log(uniform())) * sigma;
        double phi = 2.0 * M_PI * uniform();
        cv::Point p(static_cast<int>(std::lround(r * std::cos(phi))),
                    static_cast<int>(std::lround(r * std::sin(phi))));
        if (p.x * p.x + p.y * p.y <= kHalfPatchSize * kHalfPatchSize) return p;
      }
    };
    std::vector<cv::Point> pts;
    pts.reserve(512);
    while (pts.size() < 512) {
      cv::Point a = samplePoint(), b = samplePoint();
      if (a == b) continue;  // a test comparing a pixel with itself carries no information
      pts.push_back(a);
      pts.push_back(b);
    }
    return pts;
  }();
  return pattern;
}

// ------------------------------------------------------------------------------------------
// Construction: scales and per-level feature budget
// ------------------------------------------------------------------------------------------

OrbExtractor::OrbExtractor(const OrbOptions& options) : options_(options) {
  options_.validate();
  const int n = options_.n_levels;
  scale_factors_.resize(n);
  inv_scale_factors_.resize(n);
  level_sigma2_.resize(n);
  inv_level_sigma2_.resize(n);
  for (int l = 0; l < n; ++l) {
    scale_factors_[l] = std::pow(options_.scale_factor, l);
    inv_scale_factors_[l] = 1.0 / scale_factors_[l];
    level_sigma2_[l] = scale_factors_[l] * scale_factors_[l];
    inv_level_sigma2_[l] = 1.0 / level_sigma2_[l];
  }

  // Geometric budget: level l gets a share proportional to its linear size (factor^l), so the
  // keypoint density per unit of image area is similar on every level (ORB-SLAM2's formula).
  features_per_level_.assign(n, 0);
  const double factor = 1.0 / options_.scale_factor;
  double desired = options_.n_features * (1.0 - factor) / (1.0 - std::pow(factor, n));
  int sum = 0;
  for (int l = 0; l + 1 < n; ++l) {
    features_per_level_[l] = static_cast<int>(std::lround(desired));
    sum += features_per_level_[l];
    desired *= factor;
  }
  features_per_level_[n - 1] = std::max(options_.n_features - sum, 0);

  // Half-widths of a digital disk of radius 15. Using u^2 + v^2 <= r^2 + r makes the set
  // symmetric in u and v, so the centroid of a rotated patch rotates with it.
  const int r = kHalfPatchSize;
  umax_.resize(r + 1);
  for (int v = 0; v <= r; ++v) {
    umax_[v] = static_cast<int>(std::floor(std::sqrt(static_cast<double>(r * r + r - v * v))));
  }
  briefPattern();  // build the static table now rather than inside the first extract()
}

// ------------------------------------------------------------------------------------------
// Quadtree distribution (ORB-SLAM2's DistributeOctTree, re-implemented on index vectors)
// ------------------------------------------------------------------------------------------

namespace {

struct QuadNode {
  float x0, y0, x1, y1;     // [x0, x1) x [y0, y1)
  std::vector<int> idx;     // keypoints inside
  bool alive = true;
};

// Splits a node into up to four non-empty children (appended to `out`).
void splitNode(const QuadNode& n, const std::vector<cv::KeyPoint>& kps, std::vector<QuadNode>& out) {
  const float hx = std::ceil((n.x1 - n.x0) * 0.5f);
  const float hy = std::ceil((n.y1 - n.y0) * 0.5f);
  const float mx = n.x0 + hx, my = n.y0 + hy;
  QuadNode c[4] = {{n.x0, n.y0, mx, my, {}}, {mx, n.y0, n.x1, my, {}},
                   {n.x0, my, mx, n.y1, {}}, {mx, my, n.x1, n.y1, {}}};
  for (QuadNode& ch : c) ch.idx.reserve(n.idx.size());
  for (int i : n.idx) {
    const cv::Point2f& p = kps[i].pt;
    int k = (p.x < mx ? 0 : 1) + (p.y < my ? 0 : 2);
    c[k].idx.push_back(i);
  }
  for (QuadNode& ch : c) {
    if (!ch.idx.empty()) out.push_back(std::move(ch));
  }
}

bool splittable(const QuadNode& n) {
  return n.idx.size() > 1 && (n.x1 - n.x0 > 1.0f || n.y1 - n.y0 > 1.0f);
}

// The region cut into about-square columns, each keypoint in its column; empty columns left out.
std::vector<QuadNode> initialNodes(const std::vector<cv::KeyPoint>& kps, float x0, float x1,
                                   float y0, float y1) {
  const float w = x1 - x0, h = y1 - y0;
  const int n_ini = std::max(1, static_cast<int>(std::lround(w / h)));
  const float hx = w / n_ini;
  std::vector<QuadNode> nodes(n_ini);
  for (int i = 0; i < n_ini; ++i) {
    nodes[i] = {x0 + hx * i, y0, i + 1 == n_ini ? x1 : x0 + hx * (i + 1), y1, {}};
  }
  for (int i = 0; i < static_cast<int>(kps.size()); ++i) {
    int k = std::min(n_ini - 1, std::max(0, static_cast<int>((kps[i].pt.x - x0) / hx)));
    nodes[k].idx.push_back(i);
  }
  nodes.erase(std::remove_if(nodes.begin(), nodes.end(),
                             [](const QuadNode& n) { return n.idx.empty(); }),
              nodes.end());
  return nodes;
}

// Phase 1, one pass: every splittable node split. Returns how many children hold more than
// one keypoint.
int splitEveryNode(std::vector<QuadNode>& nodes, const std::vector<cv::KeyPoint>& kps) {
  std::vector<QuadNode> next;
  next.reserve(nodes.size() * 4);
  int n_multi = 0;
  for (QuadNode& n : nodes) {
    if (!splittable(n)) {
      next.push_back(std::move(n));
      continue;
    }
    size_t before = next.size();
    splitNode(n, kps, next);
    for (size_t k = before; k < next.size(); ++k) n_multi += next[k].idx.size() > 1 ? 1 : 0;
  }
  nodes.swap(next);
  return n_multi;
}

// Phase 2: one more full pass would overshoot, so the most populated nodes are split first, one
// at a time, until `alive` reaches the target or nothing splits. Returns the nodes alive.
int splitLargestFirst(std::vector<QuadNode>& nodes, const std::vector<cv::KeyPoint>& kps,
                      int target, int alive) {
  while (true) {
    const int prev = alive;
    std::vector<int> order;
    for (int i = 0; i < static_cast<int>(nodes.size()); ++i) {
      if (nodes[i].alive && splittable(nodes[i])) order.push_back(i);
    }
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return nodes[a].idx.size() > nodes[b].idx.size();
    });
    for (int i : order) {
      std::vector<QuadNode> children;
      splitNode(nodes[i], kps, children);
      nodes[i].alive = false;
      alive += static_cast<int>(children.size()) - 1;
      for (QuadNode& c : children) nodes.push_back(std::move(c));
      if (alive >= target) break;
    }
    if (alive >= target || alive == prev) return alive;
  }
}

// The strongest keypoint of each live node; a phase-2 split adds up to 3 nodes at once, so the
// overshoot is trimmed, weakest first.
std::vector<cv::KeyPoint> strongestPerNode(const std::vector<QuadNode>& nodes,
                                           const std::vector<cv::KeyPoint>& kps, int alive, int target) {
  std::vector<cv::KeyPoint> out;
  out.reserve(alive);
  for (const QuadNode& n : nodes) {
    if (!n.alive) continue;
    int best = n.idx[0];
    for (int i : n.idx) {
      if (kps[i].response > kps[best].response) best = i;
    }
    out.push_back(kps[best]);
  }
  if (static_cast<int>(out.size()) > target) {
    std::stable_sort(out.begin(), out.end(), [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
      return a.response > b.response;
    });
    out.resize(target);
  }
  return out;
}

// Keeps at most `target` keypoints spread over [x0,x1) x [y0,y1): split the region into
// quadrants until there are `target` non-empty cells (or no cell can be split), then keep the
// strongest keypoint of each cell.
std::vector<cv::KeyPoint> distributeQuadtree(const std::vector<cv::KeyPoint>& kps, float x0,
                                             float x1, float y0, float y1, int target) {
  if (target <= 0 || kps.empty()) return {};
  std::vector<QuadNode> nodes = initialNodes(kps, x0, x1, y0, y1);
  int alive = static_cast<int>(nodes.size());
  while (true) {
    const int prev = alive;
    const int n_multi = splitEveryNode(nodes, kps);
    alive = static_cast<int>(nodes.size());
    if (alive >= target || alive == prev) break;
    // Phase 1 goes on while the count stays clearly below the target.
    if (alive + 3 * n_multi > target) {
      alive = splitLargestFirst(nodes, kps, target, alive);
      break;
    }
  }
  return strongestPerNode(nodes, kps, alive, target);
}

// Intensity-centroid orientation (Rosin) over the disk of radius 15; degrees in [0, 360).
float icAngle(const cv::Mat& img, const cv::Point2f& pt, const std::vector<int>& umax) {
  const int r = static_cast<int>(umax.size()) - 1;
  const uint8_t* center = img.ptr<uint8_t>(cvRound(pt.y)) + cvRound(pt.x);
  const int step = static_cast<int>(img.step1());
  int m01 = 0, m10 = 0;
  for (int u = -r; u <= r; ++u) m10 += u * center[u];
  for (int v = 1; v <= r; ++v) {
    int v_sum = 0;
    const int d = umax[v];
    const uint8_t* below = center + v * step;
    const uint8_t* above = center - v * step;
    for (int u = -d; u <= d; ++u) {
      int plus = below[u], minus = above[u];
      v_sum += plus - minus;
      m10 += u * (plus + minus);
    }
    m01 += v * v_sum;
  }
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

// Rotated BRIEF: the pattern is rotated by the keypoint angle and each bit is the comparison
// of two blurred pixels.
void briefDescriptor(const cv::Mat& blurred, const cv::KeyPoint& kp,
                     const std::vector<cv::Point>& pattern, uint8_t* desc) {
  const float angle = kp.angle * static_cast<float>(CV_PI / 180.0);
  const float a = std::cos(angle), b = std::sin(angle);
  const uint8_t* center = blurred.ptr<uint8_t>(cvRound(kp.pt.y)) + cvRound(kp.pt.x);
  const int step = static_cast<int>(blurred.step1());
  auto value = [&](const cv::Point& p) {
    int x = cvRound(p.x * a - p.y * b);
    int y = cvRound(p.x * b + p.y * a);
    return center[y * step + x];
  };
  const cv::Point* pp = pattern.data();
  for (int byte = 0; byte < 32; ++byte) {
    int val = 0;
    for (int bit = 0; bit < 8; ++bit, pp += 2) {
      val |= (value(pp[0]) < value(pp[1]) ? 1 : 0) << bit;
    }
    desc[byte] = static_cast<uint8_t>(val);
  }
}

}  // namespace

// ------------------------------------------------------------------------------------------
// Extraction, one level at a time: pyramid, then per level FAST + quadtree + orientation and
// blur + BRIEF. Levels are independent once the pyramid exists, so they can run on two threads
// without changing the result.
// ------------------------------------------------------------------------------------------

std::vector<cv::Mat> OrbExtractor::buildPyramid(const cv::Mat& gray) const {
  std::vector<cv::Mat> pyramid(options_.n_levels);
  pyramid[0] = gray;
  for (int level = 1; level < options_.n_levels; ++level) {
    cv::Size sz(static_cast<int>(std::lround(gray.cols * inv_scale_factors_[level])),
                static_cast<int>(std::lround(gray.rows * inv_scale_factors_[level])));
    if (sz.width <= 2 * kEdgeThreshold + 2 || sz.height <= 2 * kEdgeThreshold + 2) break;
    cv::resize(pyramid[level - 1], pyramid[level], sz, 0, 0, cv::INTER_LINEAR);
  }
  return pyramid;
}

// FAST corners of one level's search area in area coordinates: one pass over the whole area at
// the initial threshold gives exactly what per-cell calls would (minus duplicates from
// overlapping cells); cells left empty are searched again with the fallback threshold, each on
// its own window so that weak corners only fill holes.
std::vector<cv::KeyPoint> OrbExtractor::fastCorners(const cv::Mat& area) const {
  const int w = area.cols, h = area.rows;
  const int n_cols = std::max(1, w / kCellSize), n_rows = std::max(1, h / kCellSize);
  const int cell_w = (w + n_cols - 1) / n_cols, cell_h = (h + n_rows - 1) / n_rows;
  std::vector<cv::KeyPoint> found;
  cv::FAST(area, found, options_.ini_th_fast, true);
  std::vector<uint8_t> occupied(n_cols * n_rows, 0);
  for (const cv::KeyPoint& kp : found) {
    int cx = std::min(n_cols - 1, static_cast<int>(kp.pt.x) / cell_w);
    int cy = std::min(n_rows - 1, static_cast<int>(kp.pt.y) / cell_h);
    occupied[cy * n_cols + cx] = 1;
  }
  std::vector<cv::KeyPoint> weak;
  for (int cy = 0; cy < n_rows; ++cy) {
    for (int cx = 0; cx < n_cols; ++cx) {
      if (occupied[cy * n_cols + cx]) continue;
      const int x0 = cx * cell_w, y0 = cy * cell_h;
      const int x1 = std::min(w, x0 + cell_w), y1 = std::min(h, y0 + cell_h);
      if (x1 <= x0 || y1 <= y0) continue;
      // Window grown by FAST's radius so corners on the cell's own pixels are testable.
      const int wx0 = std::max(0, x0 - kFastRadius), wy0 = std::max(0, y0 - kFastRadius);
      const int wx1 = std::min(w, x1 + kFastRadius), wy1 = std::min(h, y1 + kFastRadius);
      weak.clear();
      cv::FAST(area(cv::Rect(wx0, wy0, wx1 - wx0, wy1 - wy0)), weak, options_.min_th_fast, true);
      for (cv::KeyPoint kp : weak) {
        kp.pt.x += wx0;
        kp.pt.y += wy0;
        if (kp.pt.x >= x0 && kp.pt.x < x1 && kp.pt.y >= y0 && kp.pt.y < y1) found.push_back(kp);
      }
    }
  }
  return found;
}

void OrbExtractor::extractLevel(const cv::Mat& img, int level, LevelFeatures& out) const {
  out.keypoints.clear();
  out.descriptors.release();
  if (img.empty() || features_per_level_[level] <= 0) return;

  // FAST search area as in ORB-SLAM2: 16 px margins plus FAST's own 3 px radius keep every
  // keypoint >= 19 px from the border, far enough for the rotated 31 px patch and the blur.
  const int min_x = kEdgeThreshold - kFastRadius, min_y = kEdgeThreshold - kFastRadius;
  const int max_x = img.cols - kEdgeThreshold + kFastRadius;
  const int max_y = img.rows - kEdgeThreshold + kFastRadius;
  const int w = max_x - min_x, h = max_y - min_y;
  if (w <= 2 * kFastRadius + 1 || h <= 2 * kFastRadius + 1) return;

  std::vector<cv::KeyPoint> found = fastCorners(img(cv::Rect(min_x, min_y, w, h)));
  for (cv::KeyPoint& kp : found) {
    kp.pt.x += min_x;
    kp.pt.y += min_y;
  }
  out.keypoints = distributeQuadtree(found, static_cast<float>(min_x), static_cast<float>(max_x),
                                     static_cast<float>(min_y), static_cast<float>(max_y),
                                     features_per_level_[level]);
  if (out.keypoints.empty()) return;

  // Descriptors on a smoothed image (7x7, sigma 2) as ORB-SLAM2: BRIEF is noise sensitive.
  cv::Mat blurred;
  cv::GaussianBlur(img, blurred, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101);
  const std::vector<cv::Point>& pattern = briefPattern();
  const float size = static_cast<float>(kPatchSize * scale_factors_[level]);
  const float scale = static_cast<float>(scale_factors_[level]);
  out.descriptors.create(static_cast<int>(out.keypoints.size()), kDescriptorBytes, CV_8U);
  for (size_t i = 0; i < out.keypoints.size(); ++i) {
    cv::KeyPoint& kp = out.keypoints[i];
    kp.octave = level;
    kp.size = size;
    kp.angle = icAngle(img, kp.pt, umax_);
    kp.class_id = -1;
    briefDescriptor(blurred, kp, pattern, out.descriptors.ptr<uint8_t>(static_cast<int>(i)));
    if (level != 0) kp.pt *= scale;
  }
}

// Level 0 needs no pyramid and holds about a third of the pixels: a helper thread starts on it
// while this thread builds the pyramid; then both take the remaining levels, largest first,
// from one counter, so that neither waits for the other's share (levels 1-7 hold about two
// thirds of the work). Each level writes only its own slot: the result does not depend on
// which thread did what. An own thread rather than cv::parallel_for_, whose pool size is
// process-wide and set to one by the asynchronous detector.
void OrbExtractor::extractOnTwoThreads(const cv::Mat& gray, std::vector<LevelFeatures>& levels) const {
  const int n_levels = static_cast<int>(levels.size());
  std::vector<cv::Mat> pyramid;
  std::promise<void> pyramid_built;
  std::shared_future<void> pyramid_ready = pyramid_built.get_future().share();
  std::atomic<int> next_level{1};
  auto drain = [&] {
    for (int level = next_level++; level < n_levels; level = next_level++)
      extractLevel(pyramid[level], level, levels[level]);
  };
  std::future<void> helper = std::async(std::launch::async, [&] {
    extractLevel(gray, 0, levels[0]);
    pyramid_ready.get();  // rethrows when the pyramid could not be built
    drain();
  });
  try {
    pyramid = buildPyramid(gray);
  } catch (...) {
    pyramid_built.set_exception(std::current_exception());
    helper.wait();
    throw;
  }
  pyramid_built.set_value();
  drain();
  helper.get();
}

void OrbExtractor::extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints,
                           cv::Mat& descriptors) const {
  if (gray.empty() || gray.type() != CV_8UC1) {
    throw Error("OrbExtractor::extract: expected a non-empty 8-bit single-channel image, got " +
                std::string(gray.empty() ? "an empty image" : "type " + cv::typeToString(gray.type())) +
                "; convert to grayscale first (features::buildFeatureFrame does)");
  }
  std::vector<LevelFeatures> levels(options_.n_levels);
  if (options_.threads > 1) {
    extractOnTwoThreads(gray, levels);
  } else {
    const std::vector<cv::Mat> pyramid = buildPyramid(gray);
    for (int level = 0; level < options_.n_levels; ++level)
      extractLevel(pyramid[level], level, levels[level]);
  }

  size_t total = 0;
  for (const LevelFeatures& l : levels) total += l.keypoints.size();
  keypoints.clear();
  keypoints.reserve(total);
  descriptors.create(static_cast<int>(total), kDescriptorBytes, CV_8U);
  int row = 0;
  for (const LevelFeatures& l : levels) {
    if (l.keypoints.empty()) continue;
    keypoints.insert(keypoints.end(), l.keypoints.begin(), l.keypoints.end());
    l.descriptors.copyTo(descriptors.rowRange(row, row + l.descriptors.rows));
    row += l.descriptors.rows;
  }
}

}  // namespace features
}  // namespace yolo_slam
