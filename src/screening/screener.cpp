#include "yolo_slam/screening/screener.h"
#include "yolo_slam/screening/flat_box.h"
#include "yolo_slam/screening/person_mask.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/features/orb_extractor.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <random>

namespace yolo_slam {
namespace screening {

namespace {

const EnumNames<DynamicMode>& modeNames() {
  using M = DynamicMode;
  static const EnumNames<M> names = {{"off", M::Off}, {"detect", M::Detect},
                                     {"geometry", M::Geometry}, {"detect+geometry", M::DetectGeometry}};
  return names;
}

const EnumNames<ScreeningVariant>& variantNames() {
  using V = ScreeningVariant;
  static const EnumNames<V> names = {{"paper", V::Paper}, {"grow", V::Grow}, {"nearest", V::Nearest}};
  return names;
}

const EnumNames<ScreeningOptions::NoDepthRule>& noDepthNames() {
  using R = ScreeningOptions::NoDepthRule;
  static const EnumNames<R> names = {{"dynamic", R::Dynamic}, {"static", R::Static},
                                     {"nearest", R::Nearest}, {"near-dynamic", R::NearDynamic}};
  return names;
}

const OptionTable<ScreeningOptions>& screeningFields() {
  using O = ScreeningOptions;
  static const OptionTable<O> table = {
      {"Screening.varianceThreshold", &O::variance_threshold_m2, Range::positive()},
      {"Screening.probability", &O::probability, Range::open(0, 1)},
      {"Screening.maxIterations", &O::max_iterations, Range::atLeast(1)},
      {"Screening.seed", &O::seed, Range::atLeast(0)},
      {"Screening.boxDilation", &O::box_dilation, Range::closed(0, 1)},
      {"Screening.growRadius", &O::grow_radius_px, Range::positive()},
      {"Screening.growDepth", &O::grow_depth_m, Range::positive()},
      {"Screening.clusterMinFraction", &O::cluster_min_fraction, Range::fraction()},
      {"Screening.noDepthRadius", &O::no_depth_radius_px, Range::positive()},
      {"Screening.silhouetteRadius", &O::silhouette_radius_px, Range::atLeast(0)},
      {"Screening.dilationDepthOnly", &O::dilation_depth_only},
      {"Screening.rejectFlatBoxes", &O::reject_flat_boxes},
      {"Screening.occlusionRule", &O::occlusion_rule},
      {"Screening.occlusionMaxIou", &O::occlusion_max_iou, Range::fraction()},
      {"Screening.flatBoxFraction", &O::flat_box_fraction, Range::fraction()},
      {"Screening.flatBoxTolerance", &O::flat_box_tolerance, Range::positive()},
      {"Screening.flatBoxRing", &O::flat_box_ring, Range::openClosed(0, 2)},
      {"Screening.growOutside", &O::grow_outside, Range::closed(0, 1)},
      {"Screening.maskInBoxes", &O::mask_in_boxes},
      {"Screening.noDepthHoleRadius", &O::no_depth_hole_radius_px, Range::atLeast(0)},
      {"Screening.noDepthProbeRadius", &O::no_depth_probe_radius_px, Range::atLeast(0)},
  };
  return table;
}

}  // namespace

DynamicMode parseDynamicMode(const std::string& s) {
  if (const DynamicMode* m = findEnum(modeNames(), s)) return *m;
  throw Error("unknown dynamic mode '" + s + "'; use one of " + listNames(modeNames()));
}

std::string toString(DynamicMode m) { return nameOf(modeNames(), m); }

ScreeningVariant parseScreeningVariant(const std::string& s) {
  if (const ScreeningVariant* v = findEnum(variantNames(), s)) return *v;
  throw Error("unknown screening variant '" + s + "'; use one of " + listNames(variantNames()));
}

std::string toString(ScreeningVariant v) { return nameOf(variantNames(), v); }

void ScreeningOptions::validate(const std::string& where) const {
  checkOptions(*this, where, screeningFields());
  tracker.validate(where);
  temporal.validate(where);
}

ScreeningOptions ScreeningOptions::load(const Config& cfg) {
  ScreeningOptions o;
  o.mode = readEnum(cfg, "Screening.mode", o.mode, modeNames());
  o.variant = readEnum(cfg, "Screening.variant", o.variant, variantNames());
  o.no_depth = readEnum(cfg, "Screening.noDepth", o.no_depth, noDepthNames());
  readOptions(cfg, o, screeningFields());
  o.tracker = BoxTrackerOptions::load(cfg);
  o.temporal = TemporalOptions::load(cfg);
  return o;
}

double adaptiveIterations(double w, double probability, int sample_size) {
  if (w <= 0) return std::numeric_limits<double>::infinity();
  if (w >= 1) return 0.0;
  double all_inliers = std::pow(w, sample_size);
  double denom = std::log(1.0 - all_inliers);
  if (denom >= 0) return std::numeric_limits<double>::infinity();  // w^N underflowed
  return std::log(1.0 - probability) / denom;
}

Screener::Screener(const ScreeningOptions& options) : opt_(options) { opt_.validate(); }

ConsensusResult Screener::depthRansac(const std::vector<float>& depths, unsigned seed) const {
  ConsensusResult res;
  const int n = static_cast<int>(depths.size());
  if (n == 0) return res;
  if (n == 1) {
    // A single point is trivially the box's only depth cluster.
    res.members = {0};
    return res;
  }
  const double thr = opt_.variance_threshold_m2;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick_first(0, n - 1), pick_second(0, n - 2);

  // k starts unbounded (paper) and is capped by max_iterations.
  double k = std::numeric_limits<double>::infinity();
  int best_count = 0;
  std::vector<int> current, best;
  current.reserve(n);
  int iter = 0;
  while (iter < k && iter < opt_.max_iterations) {
    ++iter;
    int a = pick_first(rng);
    int b = pick_second(rng);
    if (b >= a) ++b;  // two distinct keypoints
    const double da = depths[a], db = depths[b];
    const double mean2 = 0.5 * (da + db);
    const double var1 = 0.25 * (da - db) * (da - db);  // Eq. 5 with N = 2
    current.clear();
    // The sampled pair defines the model; it belongs to the set when its own variance passes.
    if (var1 < thr) {
      current.push_back(a);
      current.push_back(b);
    }
    for (int i = 0; i < n; ++i) {
      if (i == a || i == b) continue;
      // CalcDepthVariance(var1, Dpoint3): Eq. 5 over the pair plus this point (N = 3), updated
      // incrementally: S3 = S2 + (x - m2)^2 * 2/3, var2 = S3 / 3.
      const double dx = depths[i] - mean2;
      const double var2 = (2.0 * var1 + dx * dx * (2.0 / 3.0)) / 3.0;
      if (var2 < thr) current.push_back(i);
    }
    const int count = static_cast<int>(current.size());
    if (count > best_count) {
      best_count = count;
      best.swap(current);
      k = adaptiveIterations(static_cast<double>(best_count) / n, opt_.probability, 2);
    }
  }
  res.iterations = iter;

  std::sort(best.begin(), best.end());
  res.members = std::move(best);
  return res;
}

std::vector<int> Screener::nearestCluster(const std::vector<float>& depths) const {
  const int n = static_cast<int>(depths.size());
  std::vector<int> out;
  if (n == 0) return out;
  // Half-width of Algorithm 1's consensus window for a tight pair: |d - m2| < sqrt(4.5 T).
  const double h = std::sqrt(4.5 * opt_.variance_threshold_m2);
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return depths[a] < depths[b]; });
  // Window count around every keypoint's depth (two pointers over the sorted depths).
  std::vector<int> count(n);
  int lo = 0, hi = 0, best = 0;
  for (int k = 0; k < n; ++k) {
    const double c = depths[order[k]];
    while (depths[order[lo]] <= c - h) ++lo;
    while (hi < n && depths[order[hi]] < c + h) ++hi;
    count[k] = hi - lo;
    best = std::max(best, count[k]);
  }
  const int need = std::max(1, static_cast<int>(std::ceil(opt_.cluster_min_fraction * best)));
  // Nearest sizeable window; then climb to the local maximum of the count so the window is
  // centred on the cluster rather than on its near edge.
  int k = 0;
  while (count[k] < need) ++k;
  while (k + 1 < n && count[k + 1] >= count[k] && depths[order[k + 1]] < depths[order[k]] + h) ++k;
  const double c = depths[order[k]];
  for (int i = 0; i < n; ++i)
    if (std::abs(depths[i] - c) < h) out.push_back(i);
  return out;
}

void Screener::grow(const std::vector<cv::Point2f>& pts, const std::vector<float>& depths,
                    std::vector<uint8_t>& member) const {
  const size_t n = pts.size();
  const float r2 = static_cast<float>(opt_.grow_radius_px * opt_.grow_radius_px);
  const float dd = static_cast<float>(opt_.grow_depth_m);
  std::vector<int> queue;
  queue.reserve(n);
  for (size_t i = 0; i < n; ++i)
    if (member[i]) queue.push_back(static_cast<int>(i));
  // Breadth-first single linkage from every member; each keypoint enters the queue once.
  for (size_t q = 0; q < queue.size(); ++q) {
    const int m = queue[q];
    for (size_t i = 0; i < n; ++i) {
      if (member[i]) continue;
      if (std::abs(depths[i] - depths[m]) >= dd) continue;
      const float dx = pts[i].x - pts[m].x, dy = pts[i].y - pts[m].y;
      if (dx * dx + dy * dy >= r2) continue;
      member[i] = 1;
      queue.push_back(static_cast<int>(i));
    }
  }
}

cv::Rect2f dilate(const cv::Rect2f& r, double f) {
  const float dx = static_cast<float>(r.width * f), dy = static_cast<float>(r.height * f);
  return {r.x - dx, r.y - dy, r.width + 2 * dx, r.height + 2 * dy};
}

bool inside(const cv::Rect2f& r, const cv::Point2f& p) {
  return p.x >= r.x && p.y >= r.y && p.x < r.x + r.width && p.y < r.y + r.height;
}

namespace {

// One RANSAC region of screen(): a dilated box, or the whole image in geometry mode. The
// buffers are reused from region to region.
struct Region {
  unsigned index = 0;                // the box's index (0 in geometry mode); seeds the RNG
  const cv::Rect2f* box = nullptr;   // the dilated box; null in geometry mode
  const cv::Rect2f* core = nullptr;  // the detected box when dilation_depth_only, else null
  std::vector<int> idx;              // every keypoint of the region
  // Of those, the keypoints with depth, their depths and positions, and which of them are
  // the person (set by findPerson).
  std::vector<int> with_depth;
  std::vector<float> depths;
  std::vector<cv::Point2f> pts;
  std::vector<uint8_t> member;
};

// What the rules after the person sets read of the image (each may be empty): the depth image
// (metres), the grown person mask and the distance to it (person_mask.h).
struct PersonPixels {
  cv::Mat depth, mask, distance;
};

// The depth image for the silhouette rule and screening beyond the boxes (may be empty);
// throws unless it is CV_32FC1 of the frame's size.
void checkDepthImage(const features::FeatureFrame& frame, const cv::Mat& depth_m) {
  if (depth_m.empty()) return;
  if (depth_m.type() != CV_32FC1 || depth_m.cols != frame.width || depth_m.rows != frame.height)
    throw Error("screening: the depth image for the silhouette rule must be CV_32FC1 metres of "
                "the frame's size (" + std::to_string(frame.width) + "x" +
                std::to_string(frame.height) + ")");
}

// The modes with geometry need a depth per keypoint.
void checkDepths(const ScreeningOptions& o, const features::FeatureFrame& frame) {
  const size_t n = frame.keypoints.size();
  if (frame.depth.size() != n && o.mode != DynamicMode::Off && o.mode != DynamicMode::Detect) {
    throw Error("screening: frame has " + std::to_string(n) + " keypoints but " +
                std::to_string(frame.depth.size()) + " depths; build it with buildFeatureFrame");
  }
}

// Algorithm 1 (or the nearest cluster), then the grow step, over the region's keypoints with
// depth. Returns the RANSAC iterations.
int findPerson(const Screener& s, const features::FeatureFrame& frame, Region& r) {
  const ScreeningOptions& o = s.options();
  r.depths.clear();
  r.with_depth.clear();
  r.pts.clear();
  for (int i : r.idx) {
    if (frame.depth[i] > 0) {
      r.depths.push_back(frame.depth[i]);
      r.with_depth.push_back(i);
      r.pts.push_back(frame.keypoints[i].pt);
    }
  }
  r.member.assign(r.depths.size(), 0);
  int iterations = 0;
  if (o.variant == ScreeningVariant::Nearest) {
    for (int m : s.nearestCluster(r.depths)) r.member[m] = 1;
  } else {
    // Region k reseeds the RNG with seed + 7919 k: regions are independent of each other and
    // of previous frames.
    ConsensusResult c = s.depthRansac(r.depths, o.seed + 7919u * r.index);
    iterations = c.iterations;
    for (int m : c.members) r.member[m] = 1;
  }
  if (o.variant != ScreeningVariant::Paper) s.grow(r.pts, r.depths, r.member);
  return iterations;
}

// The flat-box rule on the person's set of a box region.
bool isFlatBox(const ScreeningOptions& o, const features::FeatureFrame& frame, const Region& r,
               const detection::Boxes& boxes) {
  std::vector<int> cluster;
  for (size_t m = 0; m < r.member.size(); ++m)
    if (r.member[m]) cluster.push_back(r.with_depth[m]);
  FlatBoxOptions fo;
  fo.ring = o.flat_box_ring;
  fo.tolerance = o.flat_box_tolerance;
  fo.fraction = o.flat_box_fraction;
  fo.seed = o.seed + 7919u * r.index;
  std::vector<cv::Rect2f> others;
  for (size_t k = 0; k < boxes.size(); ++k)
    if (k != r.index) others.push_back(dilate(boxes[k].rect, o.box_dilation));
  return testFlatBox(frame, *r.box, cluster, fo, others).flat;
}

// Whether a depth pixel within [lo, hi] lies in the keypoint's window (radius times its scale).
bool personDepthNear(const cv::Mat& depth_m, const cv::KeyPoint& kp, double radius_px, float lo,
                     float hi) {
  const int r = std::max(1, static_cast<int>(std::lround(radius_px * kp.size / 31.f)));
  const cv::Rect img(0, 0, depth_m.cols, depth_m.rows);
  const cv::Rect win = cv::Rect(static_cast<int>(std::lround(kp.pt.x)) - r,
                                static_cast<int>(std::lround(kp.pt.y)) - r, 2 * r + 1,
                                2 * r + 1) & img;
  for (int v = win.y; v < win.br().y; ++v) {
    const float* row = depth_m.ptr<float>(v);
    for (int u = win.x; u < win.br().x; ++u)
      if (row[u] >= lo && row[u] <= hi) return true;
  }
  return false;
}

// Silhouette rule: keypoints of the box left static whose depth is missing or outside the
// person's range [lo, hi] (+- grow_depth_m), with a person-depth pixel within the radius.
// Returns how many it dropped.
int markSilhouette(const ScreeningOptions& o, const features::FeatureFrame& frame, const Region& r,
                   const cv::Mat& depth_m, std::vector<uint8_t>& drop) {
  float lo = std::numeric_limits<float>::max(), hi = 0.f;
  for (size_t m = 0; m < r.member.size(); ++m)
    if (r.member[m]) lo = std::min(lo, r.depths[m]), hi = std::max(hi, r.depths[m]);
  if (hi <= 0.f) return 0;
  lo -= static_cast<float>(o.grow_depth_m);
  hi += static_cast<float>(o.grow_depth_m);
  int dropped = 0;
  for (int i : r.idx) {
    if (drop[i] || !inside(*r.box, frame.keypoints[i].pt)) continue;
    const float d = frame.depth[i];
    if (d >= lo && d <= hi) continue;  // at the person's depth: Algorithm 1's call stands
    if (personDepthNear(depth_m, frame.keypoints[i], o.silhouette_radius_px, lo, hi)) {
      drop[i] = 1;
      ++dropped;
    }
  }
  return dropped;
}

// What the nearest valid depth pixels around a keypoint without depth show.
enum class Probe { Person, Other, Nothing };

// The first square ring around the keypoint (radius 0 to radius_px times its scale) holding a
// valid depth pixel: Person when one of them lies on the grown person mask, else Other;
// Nothing when no ring does.
Probe probeDepth(const cv::Mat& depth_m, const cv::Mat& person_mask, const cv::KeyPoint& kp,
                 double radius_px) {
  const int rmax = std::max(1, static_cast<int>(std::lround(radius_px * kp.size / 31.f)));
  const int cx = static_cast<int>(std::lround(kp.pt.x)), cy = static_cast<int>(std::lround(kp.pt.y));
  for (int k = 0; k <= rmax; ++k) {
    bool any = false, person = false;
    for (int v = std::max(0, cy - k); v <= std::min(depth_m.rows - 1, cy + k); ++v) {
      const float* row = depth_m.ptr<float>(v);
      const bool edge_row = v == cy - k || v == cy + k;
      const int step = edge_row || k == 0 ? 1 : 2 * k;  // inner rows: the two side pixels only
      for (int u = cx - k; u <= cx + k; u += step) {
        if (u < 0 || u >= depth_m.cols || row[u] <= 0.f) continue;
        any = true;
        person = person || personCellAt(person_mask, cv::Point2f(u, v));
      }
    }
    if (any) return person ? Probe::Person : Probe::Other;
  }
  return Probe::Nothing;
}

// NearDynamic: whether a person keypoint with depth lies within no_depth_radius_px of p.
bool memberNear(const ScreeningOptions& o, const Region& r, const cv::Point2f& p) {
  const float nd2 = static_cast<float>(o.no_depth_radius_px * o.no_depth_radius_px);
  for (size_t m = 0; m < r.pts.size(); ++m) {
    if (!r.member[m]) continue;
    const float dx = r.pts[m].x - p.x, dy = r.pts[m].y - p.y;
    if (dx * dx + dy * dy < nd2) return true;
  }
  return false;
}

// Nearest: the label of the closest keypoint with depth within grow_radius_px (0 if none).
uint8_t nearestLabel(const ScreeningOptions& o, const Region& r, const cv::Point2f& p) {
  float best = static_cast<float>(o.grow_radius_px * o.grow_radius_px);
  uint8_t label = 0;
  for (size_t m = 0; m < r.pts.size(); ++m) {
    const float dx = r.pts[m].x - p.x, dy = r.pts[m].y - p.y, d2 = dx * dx + dy * dy;
    if (d2 < best) {
      best = d2;
      label = r.member[m];
    }
  }
  return label;
}

// The no-depth rule over the region's keypoints without depth; person.distance (empty when
// screening beyond the boxes is off) narrows near-dynamic to holes near a person's pixels, and
// the depth probe (no_depth_probe_radius_px, needs person.depth and person.mask) to holes
// whose nearest valid depth is the person's.
void markNoDepth(const ScreeningOptions& o, const features::FeatureFrame& frame, const Region& r,
                 const PersonPixels& person, std::vector<uint8_t>& drop) {
  using Rule = ScreeningOptions::NoDepthRule;
  if (o.no_depth == Rule::Static) return;
  const bool probe = r.box && o.no_depth_probe_radius_px > 0 && !person.depth.empty() && !person.mask.empty();
  for (int i : r.idx) {
    if (frame.depth[i] > 0) continue;
    const cv::Point2f p = frame.keypoints[i].pt;
    if (r.core && !inside(*r.core, p)) continue;  // dilation ring: depth only
    bool dynamic = true;  // Rule::Dynamic
    if (o.no_depth == Rule::NearDynamic) {
      dynamic = memberNear(o, r, p) &&
                (person.distance.empty() || distanceAt(person.distance, p) <= o.no_depth_hole_radius_px);
    }
    if (o.no_depth == Rule::Nearest) dynamic = nearestLabel(o, r, p) != 0;
    // The hole's own surroundings overrule the neighbours: background all around, background.
    if (dynamic && probe)
      dynamic = probeDepth(person.depth, person.mask, frame.keypoints[i], o.no_depth_probe_radius_px) != Probe::Other;
    if (dynamic) drop[i] = 1;
  }
}

// Marks one region whose person set findPerson found: the set is dropped, then the silhouette
// and no-depth rules. (A flat box is not marked at all.)
void markRegion(const ScreeningOptions& o, const features::FeatureFrame& frame, const Region& r,
                const PersonPixels& person, std::vector<uint8_t>& drop, ScreeningStats& st) {
  for (size_t m = 0; m < r.member.size(); ++m)
    if (r.member[m]) drop[r.with_depth[m]] = 1;
  if (r.box && !person.depth.empty() && o.silhouette_radius_px > 0)
    st.silhouette += markSilhouette(o, frame, r, person.depth, drop);
  markNoDepth(o, frame, r, person, drop);
}

// The grow seeds of a region's person set: its keypoints with depth, their depth range widened
// by grow_depth_m, and the box widened by grow_outside past the dilation.
PersonSeeds personSeeds(const ScreeningOptions& o, const Region& r, const cv::Rect2f& box) {
  PersonSeeds p;
  p.lo = std::numeric_limits<float>::max();
  for (size_t m = 0; m < r.member.size(); ++m) {
    if (!r.member[m]) continue;
    p.pts.push_back(r.pts[m]);
    p.lo = std::min(p.lo, r.depths[m]);
    p.hi = std::max(p.hi, r.depths[m]);
  }
  p.lo -= static_cast<float>(o.grow_depth_m);
  p.hi += static_cast<float>(o.grow_depth_m);
  p.limit = dilate(box, o.box_dilation + o.grow_outside);
  return p;
}

// Screening beyond the boxes: the person pixels of every box not left alone as flat, grown
// over the depth image; returns the distance image to them (empty when off or without depth).
cv::Mat personDistanceOf(const ScreeningOptions& o, const std::vector<Region>& regions,
                         const std::vector<uint8_t>& flat, const detection::Boxes& boxes,
                         const cv::Mat& depth_m, cv::Mat& mask) {
  if (o.no_depth_hole_radius_px <= 0 || depth_m.empty()) return cv::Mat();
  std::vector<PersonSeeds> people;
  for (size_t b = 0; b < regions.size(); ++b)
    if (!flat[b]) people.push_back(personSeeds(o, regions[b], boxes[b].rect));
  mask = growPersonMask(depth_m, people);
  return personDistance(mask);
}

// Every box for the in-box rule: its region and its person's depth range (personSeeds's).
std::vector<BoxPerson> boxPeople(const ScreeningOptions& o, const std::vector<Region>& regions,
                                 const std::vector<uint8_t>& flat, const detection::Boxes& boxes) {
  std::vector<BoxPerson> out(regions.size());
  for (size_t b = 0; b < regions.size(); ++b) {
    const PersonSeeds p = personSeeds(o, regions[b], boxes[b].rect);
    out[b].region = *regions[b].box;
    out[b].lo = p.lo;
    out[b].hi = p.hi;
    out[b].keeps_all = flat[b] || p.pts.empty();
  }
  return out;
}

// The keypoints of a region's person set.
std::vector<int> personSet(const Region& r) {
  std::vector<int> out;
  for (size_t m = 0; m < r.member.size(); ++m)
    if (r.member[m]) out.push_back(r.with_depth[m]);
  return out;
}

// Share of a region's keypoints with depth that are its person.
double personFill(const Region& r) {
  return r.with_depth.empty() ? 0.0 : static_cast<double>(personSet(r).size()) / r.with_depth.size();
}

float iou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const float inter = (a & b).area();
  const float uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.f;
}

// Median depth of keypoints with depth (+infinity for none).
float medianDepth(const features::FeatureFrame& frame, const std::vector<int>& idx) {
  std::vector<float> d;
  d.reserve(idx.size());
  for (int i : idx) d.push_back(frame.depth[i]);
  if (d.empty()) return std::numeric_limits<float>::infinity();
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

// Share of a person set that another region claimed as its own person, above which the set is
// taken to be that region's person seen through this box.
constexpr double kClaimedShare = 0.5;

// The occlusion rule: a box whose person set is mostly the person of another overlapping box
// (not a duplicate detection) that its person fills better is screened again without them.
void resolveOcclusions(const Screener& s, const features::FeatureFrame& frame, const detection::Boxes& boxes,
                       std::vector<Region>& regions, ScreeningStats& st) {
  const ScreeningOptions& o = s.options();
  std::vector<std::vector<int>> sets;
  std::vector<double> fill;
  for (const Region& r : regions) {
    std::vector<int> set = personSet(r);
    std::sort(set.begin(), set.end());
    sets.push_back(std::move(set));
    fill.push_back(personFill(r));
  }
  for (size_t b = 0; b < regions.size(); ++b) {
    if (sets[b].empty()) continue;
    for (size_t c = 0; c < regions.size(); ++c) {
      if (c == b || fill[c] < fill[b] || iou(boxes[b].rect, boxes[c].rect) > o.occlusion_max_iou) continue;
      std::vector<int> shared;
      std::set_intersection(sets[b].begin(), sets[b].end(), sets[c].begin(), sets[c].end(),
                            std::back_inserter(shared));
      if (shared.size() < kClaimedShare * sets[b].size()) continue;
      Region& r = regions[b];
      const Region before = r;
      r.idx.erase(std::remove_if(r.idx.begin(), r.idx.end(),
                                 [&](int i) { return std::binary_search(sets[c].begin(), sets[c].end(), i); }),
                  r.idx.end());
      st.iterations += findPerson(s, frame, r);
      // The person behind an occluder is deeper than it. A nearer set means the shared
      // keypoints were two people side by side at one depth, and the first set was right.
      if (medianDepth(frame, personSet(r)) < medianDepth(frame, shared)) {
        r = before;
        continue;
      }
      ++st.occluded_boxes;
      break;
    }
  }
}

// Marks the region of every box (flat boxes left alone), then, with screening beyond the
// boxes, the keypoints outside every box on or near a person's grown pixels.
void markBoxes(const Screener& s, const features::FeatureFrame& frame, const detection::Boxes& boxes,
               const std::vector<Region>& regions, const cv::Mat& depth_m,
               const std::vector<uint8_t>& in_any, std::vector<uint8_t>& drop, ScreeningStats& st) {
  const ScreeningOptions& o = s.options();
  std::vector<uint8_t> flat(regions.size(), 0);
  for (size_t b = 0; b < regions.size(); ++b) {
    flat[b] = o.reject_flat_boxes && isFlatBox(o, frame, regions[b], boxes);
    st.flat_boxes += flat[b];
  }
  PersonPixels person;
  person.depth = depth_m;
  person.distance = personDistanceOf(o, regions, flat, boxes, depth_m, person.mask);
  for (size_t b = 0; b < regions.size(); ++b)
    if (!flat[b]) markRegion(o, frame, regions[b], person, drop, st);
  if (person.distance.empty()) return;
  if (o.mask_in_boxes)
    st.grown_in_boxes += markGrownInBoxes(frame, person.mask, boxPeople(o, regions, flat, boxes), in_any, drop);
  st.grown_outside += markGrownOutside(frame, person.mask, in_any, drop);
  st.depth_holes += markHolesOutside(frame, person.distance, o.no_depth_hole_radius_px, in_any, drop);
}

// Box modes: the keypoints of each dilated box (in_any) are dropped (detect) or screened.
void screenBoxes(const Screener& s, const features::FeatureFrame& frame,
                 const detection::Boxes& boxes, const cv::Mat& depth_m,
                 std::vector<uint8_t>& in_any, std::vector<uint8_t>& drop, ScreeningStats& st) {
  const ScreeningOptions& o = s.options();
  std::vector<cv::Rect2f> dilated(boxes.size());
  std::vector<Region> regions(boxes.size());
  for (size_t b = 0; b < boxes.size(); ++b) {
    dilated[b] = dilate(boxes[b].rect, o.box_dilation);
    Region& r = regions[b];
    r.index = static_cast<unsigned>(b);
    r.box = &dilated[b];
    r.core = o.dilation_depth_only ? &boxes[b].rect : nullptr;
    for (size_t i = 0; i < frame.keypoints.size(); ++i) {
      if (inside(dilated[b], frame.keypoints[i].pt)) {
        r.idx.push_back(static_cast<int>(i));
        in_any[i] = 1;
      }
    }
    if (o.mode == DynamicMode::Detect) {
      for (int i : r.idx) drop[i] = 1;
    } else {
      st.iterations += findPerson(s, frame, r);
    }
  }
  if (o.mode == DynamicMode::Detect) return;
  if (o.occlusion_rule && regions.size() > 1) resolveOcclusions(s, frame, boxes, regions, st);
  markBoxes(s, frame, boxes, regions, depth_m, in_any, drop, st);
}

// Writes the drops into frame.dynamic and counts those of the keypoints in a region (the
// drops outside every box are counted by their rules).
void applyDrops(const std::vector<uint8_t>& in_any, const std::vector<uint8_t>& drop,
                features::FeatureFrame& frame, ScreeningStats& st) {
  for (size_t i = 0; i < in_any.size(); ++i) {
    if (!in_any[i]) {
      if (drop[i]) frame.dynamic[i] = 1;
      continue;
    }
    ++st.in_boxes;
    if (drop[i]) {
      frame.dynamic[i] = 1;
      ++st.dropped;
    } else {
      ++st.kept;
    }
  }
}

}  // namespace

ScreeningStats Screener::screen(features::FeatureFrame& frame, const detection::Boxes& boxes,
                                const cv::Mat& depth_m) const {
  Stopwatch sw;
  ScreeningStats st;
  const size_t n = frame.keypoints.size();
  if (frame.dynamic.size() != n) frame.dynamic.resize(n, 0);
  checkDepths(opt_, frame);
  if (opt_.mode != DynamicMode::Off) {
    checkDepthImage(frame, depth_m);
    std::vector<uint8_t> in_any(n, 0), drop(n, 0);
    if (opt_.mode == DynamicMode::Geometry) {
      // The whole image is one region.
      Region r;
      for (size_t i = 0; i < n; ++i) r.idx.push_back(static_cast<int>(i));
      std::fill(in_any.begin(), in_any.end(), 1);
      st.iterations += findPerson(*this, frame, r);
      markRegion(opt_, frame, r, PersonPixels(), drop, st);
    } else {
      screenBoxes(*this, frame, boxes, depth_m, in_any, drop, st);
      frame.boxed.assign(n, 0);
      for (size_t i = 0; i < n; ++i) frame.boxed[i] = in_any[i] && !drop[i] && !frame.dynamic[i];
    }
    applyDrops(in_any, drop, frame, st);
  }
  st.ms = sw.ms();
  return st;
}

// ---------------------------------------------------------------------------------------------

double ScreeningMetrics::dynamicRecall() const {
  return dynamic_total > 0 ? static_cast<double>(dynamic_dropped) / dynamic_total : 1.0;
}

double ScreeningMetrics::personRecall() const {
  return person_total > 0 ? static_cast<double>(person_dropped) / person_total : 1.0;
}

double ScreeningMetrics::dynamicRecallInBoxes() const {
  const int n = dynamic_total - dynamic_outside_boxes;
  return n > 0 ? static_cast<double>(dynamic_dropped - dynamic_outside_dropped) / n : 1.0;
}

double ScreeningMetrics::staticRetention() const {
  return static_in_boxes > 0 ? static_cast<double>(static_in_boxes_kept) / static_in_boxes : 1.0;
}

double ScreeningMetrics::staticDropRate() const {
  return static_total > 0 ? static_cast<double>(static_dropped) / static_total : 0.0;
}

double ScreeningMetrics::staticDropRateOffOutline() const {
  const int total = static_total - static_on_outline;
  return total > 0 ? static_cast<double>(static_dropped - static_on_outline_dropped) / total : 0.0;
}

ScreeningMetrics& ScreeningMetrics::operator+=(const ScreeningMetrics& o) {
  dynamic_total += o.dynamic_total;
  dynamic_dropped += o.dynamic_dropped;
  dynamic_outside_boxes += o.dynamic_outside_boxes;
  dynamic_outside_dropped += o.dynamic_outside_dropped;
  person_total += o.person_total;
  person_dropped += o.person_dropped;
  static_in_boxes += o.static_in_boxes;
  static_in_boxes_kept += o.static_in_boxes_kept;
  static_total += o.static_total;
  static_dropped += o.static_dropped;
  static_on_outline += o.static_on_outline;
  static_on_outline_dropped += o.static_on_outline_dropped;
  return *this;
}

void to_json(Json& j, const ScreeningMetrics& m) {
  j = Json{{"dynamic_keypoints", m.dynamic_total},
           {"dropped", m.dynamic_dropped},
           {"dynamic_recall", jsonRatio(m.dynamic_dropped, m.dynamic_total)},
           {"dynamic_outside_boxes", m.dynamic_outside_boxes},
           {"dynamic_outside_dropped", m.dynamic_outside_dropped},
           {"dynamic_recall_in_boxes", jsonRatio(m.dynamic_dropped - m.dynamic_outside_dropped,
                                                 m.dynamic_total - m.dynamic_outside_boxes)},
           {"person_keypoints", m.person_total},
           {"person_dropped", m.person_dropped},
           {"person_recall", jsonRatio(m.person_dropped, m.person_total)},
           {"object_keypoints", m.dynamic_total - m.person_total},
           {"object_recall", jsonRatio(m.dynamic_dropped - m.person_dropped, m.dynamic_total - m.person_total)},
           {"static_in_boxes", m.static_in_boxes},
           {"kept", m.static_in_boxes_kept},
           {"static_retention", jsonRatio(m.static_in_boxes_kept, m.static_in_boxes)},
           {"static_keypoints", m.static_total},
           {"static_dropped", m.static_dropped},
           {"static_drop_rate", jsonRatio(m.static_dropped, m.static_total)},
           {"static_on_outline", m.static_on_outline},
           {"static_on_outline_dropped", m.static_on_outline_dropped},
           {"static_drop_rate_off_outline", jsonRatio(m.static_dropped - m.static_on_outline_dropped,
                                                      m.static_total - m.static_on_outline)}};
}

ScreeningStats& ScreeningStats::operator+=(const ScreeningStats& o) {
  in_boxes += o.in_boxes;
  kept += o.kept;
  dropped += o.dropped;
  iterations += o.iterations;
  ms += o.ms;
  flat_boxes += o.flat_boxes;
  silhouette += o.silhouette;
  occluded_boxes += o.occluded_boxes;
  grown_outside += o.grown_outside;
  grown_in_boxes += o.grown_in_boxes;
  depth_holes += o.depth_holes;
  return *this;
}

void to_json(Json& j, const ScreeningStats& s) {
  j = Json{{"in_boxes", s.in_boxes},     {"kept", s.kept},
           {"dropped", s.dropped},       {"silhouette", s.silhouette},
           {"flat_boxes", s.flat_boxes}, {"occluded_boxes", s.occluded_boxes},
           {"grown_outside", s.grown_outside}, {"grown_in_boxes", s.grown_in_boxes},
           {"depth_holes", s.depth_holes},
           {"iterations", s.iterations}};
}

namespace {

// A static keypoint at pixel (x, y) whose FAST circle (its radius at the keypoint's pyramid
// level) reaches a dynamic pixel of `mask`. Only the disc around the keypoint is read: a distance
// transform of the whole mask per frame took a quarter of the frame thread's time on the
// synthetic sequences, and these metrics must not slow the pipeline they measure.
bool onOutline(const cv::KeyPoint& kp, const cv::Mat& mask, int x, int y) {
  const double r = features::OrbExtractor::kFastRadius * features::OrbExtractor::levelScale(kp);
  const int ri = static_cast<int>(r);
  const double r2 = r * r;
  for (int dy = -ri; dy <= ri; ++dy) {
    const int yy = y + dy;
    if (yy < 0 || yy >= mask.rows) continue;
    const uint8_t* row = mask.ptr<uint8_t>(yy);
    for (int dx = -ri; dx <= ri; ++dx) {
      const int xx = x + dx;
      if (xx < 0 || xx >= mask.cols || dx * dx + dy * dy > r2) continue;
      if (row[xx] > 127) return true;
    }
  }
  return false;
}

}  // namespace

ScreeningMetrics evaluateScreening(const features::FeatureFrame& frame, const cv::Mat& mask,
                                   const detection::Boxes& boxes, int ignore_border_px) {
  if (mask.empty() || mask.type() != CV_8UC1)
    throw Error("screening metrics: ground-truth mask must be a non-empty 8-bit single-channel image");
  if (frame.width > 0 && frame.height > 0 &&
      (mask.cols != frame.width || mask.rows != frame.height)) {
    throw Error("screening metrics: mask is " + std::to_string(mask.cols) + "x" +
                std::to_string(mask.rows) + " but the image is " + std::to_string(frame.width) +
                "x" + std::to_string(frame.height) + "; use the mask of this frame");
  }
  cv::Mat core_dyn, near_dyn;  // mask eroded / dilated by the ignored border
  if (ignore_border_px > 0) {
    const cv::Mat k = cv::getStructuringElement(
        cv::MORPH_ELLIPSE, cv::Size(2 * ignore_border_px + 1, 2 * ignore_border_px + 1));
    cv::Mat bin = mask > 127;
    cv::erode(bin, core_dyn, k);
    cv::dilate(bin, near_dyn, k);
  }
  ScreeningMetrics m;
  for (size_t i = 0; i < frame.keypoints.size(); ++i) {
    const cv::Point2f& p = frame.keypoints[i].pt;
    const int x = std::min(mask.cols - 1, std::max(0, static_cast<int>(std::lround(p.x))));
    const int y = std::min(mask.rows - 1, std::max(0, static_cast<int>(std::lround(p.y))));
    const bool dyn_gt = mask.at<uint8_t>(y, x) > 127;
    if (ignore_border_px > 0 && (dyn_gt ? !core_dyn.at<uint8_t>(y, x) : near_dyn.at<uint8_t>(y, x)))
      continue;
    const bool dropped = i < frame.dynamic.size() && frame.dynamic[i];
    bool in_box = false;
    for (const auto& b : boxes) in_box = in_box || inside(b.rect, p);
    if (dyn_gt) {
      ++m.dynamic_total;
      m.dynamic_dropped += dropped ? 1 : 0;
      if (mask.at<uint8_t>(y, x) == 255) {
        ++m.person_total;
        m.person_dropped += dropped ? 1 : 0;
      }
      if (!in_box) {
        ++m.dynamic_outside_boxes;
        m.dynamic_outside_dropped += dropped ? 1 : 0;
      }
      continue;
    }
    ++m.static_total;
    m.static_dropped += dropped ? 1 : 0;
    if (onOutline(frame.keypoints[i], mask, x, y)) {
      ++m.static_on_outline;
      m.static_on_outline_dropped += dropped ? 1 : 0;
    }
    if (in_box) {
      ++m.static_in_boxes;
      m.static_in_boxes_kept += dropped ? 0 : 1;
    }
  }
  return m;
}

cv::Mat loadMask(const std::string& path) {
  cv::Mat m = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (m.empty())
    throw Error(path + ": ground-truth mask missing or unreadable; expected an 8-bit PNG "
                       "(0 static, 255 person, 128-254 other dynamic) of the image's size");
  return m;
}

}  // namespace screening
}  // namespace yolo_slam
