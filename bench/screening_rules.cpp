// Which screening rule drops which keypoints: replays Screener::screen over a yolo_slam_synth
// sequence with the boxes a yolo_slam_run run screened (RUN/boxes_screened.txt), and attributes
// the static keypoints the defaults drop (and the people's keypoints they drop) to the rules by
// turning one rule off at a time:
//   screening_rules --sequence SEQ --run RUN [--stride N] [--max-frames N] [--set KEY=VALUE]...
//                   [--detected-iou X]
// The configuration is SEQ/camera.yaml with the --set overrides (the same keys as yolo_slam_run).
// Only Screener::screen is replayed: the static-box veto, motion screening and the adaptive
// feature budget of the run are not (set ORBextractor.nFeatures to the run's mean budget to
// come closer). Also prints how far the wrongly dropped static keypoints lie from the nearest
// person pixel (ground-truth mask): a keypoint a few pixels off a person straddles its outline;
// and where the person keypoints left static are (outside the boxes, without depth, or at
// which depth against what their box dropped: another person standing behind the boxed one).
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/screening/screener.h"
#include "gt_boxes.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace yolo_slam;
using namespace yolo_slam::screening;

namespace {

// Boxes per rgb stamp from RUN/boxes_screened.txt
// ("rgb_stamp index label x1 y1 x2 y2 score tracked").
std::map<std::string, detection::Boxes> readScreenedBoxes(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": not found; pass the --out folder of a yolo_slam_run run");
  std::map<std::string, detection::Boxes> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream is(line);
    std::string stamp, label;
    int index = 0, tracked = 0;
    float x1, y1, x2, y2, score;
    if (!(is >> stamp >> index >> label >> x1 >> y1 >> x2 >> y2 >> score >> tracked)) continue;
    detection::Box b;
    b.label = label;
    b.score = score;
    b.rect = cv::Rect2f(x1, y1, x2 - x1, y2 - y1);
    out[stamp].push_back(b);
  }
  return out;
}

struct Variant {
  std::string name;
  std::function<void(ScreeningOptions&)> change;
};

// One rule off at a time (the first row: the configuration as given).
std::vector<Variant> variants() {
  using R = ScreeningOptions::NoDepthRule;
  return {
      {"as configured", [](ScreeningOptions&) {}},
      {"silhouette rule off", [](ScreeningOptions& o) { o.silhouette_radius_px = 0; }},
      {"no-depth in boxes static", [](ScreeningOptions& o) { o.no_depth = R::Static; }},
      {"grow step off (growRadius 0.01)", [](ScreeningOptions& o) { o.grow_radius_px = 0.01; }},
      {"beyond the boxes off", [](ScreeningOptions& o) { o.no_depth_hole_radius_px = 0; }},
      {"growOutside 0", [](ScreeningOptions& o) { o.grow_outside = 0; }},
      {"boxDilation 0", [](ScreeningOptions& o) { o.box_dilation = 0; }},
      {"occlusion rule off", [](ScreeningOptions& o) { o.occlusion_rule = false; }},
  };
}

// Static / person keypoints a configuration drops, split by where they are.
struct Split {
  long static_total = 0, static_dropped = 0;
  long in_box_depth = 0, in_box_hole = 0, outside_depth = 0, outside_hole = 0;  // static dropped
  long person_total = 0, person_dropped = 0;
};

bool inAnyBox(const detection::Boxes& boxes, double dilation, const cv::Point2f& p) {
  for (const auto& b : boxes)
    if (inside(dilate(b.rect, dilation), p)) return true;
  return false;
}

void count(const features::FeatureFrame& f, const cv::Mat& mask, const detection::Boxes& boxes,
           double dilation, Split& s) {
  for (size_t i = 0; i < f.keypoints.size(); ++i) {
    const cv::Point2f p = f.keypoints[i].pt;
    const int x = std::min(mask.cols - 1, std::max(0, static_cast<int>(std::lround(p.x))));
    const int y = std::min(mask.rows - 1, std::max(0, static_cast<int>(std::lround(p.y))));
    const uint8_t m = mask.at<uint8_t>(y, x);
    const bool dropped = f.dynamic[i] != 0;
    if (m == 255) {
      ++s.person_total;
      s.person_dropped += dropped;
    }
    if (m > 127) continue;
    ++s.static_total;
    if (!dropped) continue;
    ++s.static_dropped;
    const bool boxed = inAnyBox(boxes, dilation, p), depth = f.depth[i] > 0;
    if (boxed) (depth ? s.in_box_depth : s.in_box_hole)++;
    else (depth ? s.outside_depth : s.outside_hole)++;
  }
}

// Person keypoints a configuration leaves static, by where they are and, in a box with depth,
// how their depth compares with the median depth of the keypoints the box dropped: a person
// more than kBehindM behind that is mostly another person, standing behind the boxed one.
constexpr double kBehindM = 0.5;

struct Misses {
  long outside_depth = 0, outside_hole = 0, in_box_hole = 0, box_dropped_nothing = 0;
  long nearer = 0, within = 0, behind = 0, far_behind = 0;
  long far_behind_unboxed = 0;  // of far_behind: a ground-truth person around it has no box
};

// A ground-truth box is detected when a screened box overlaps it by this IoU (--detected-iou).
constexpr float kDefaultDetectedIou = 0.5f;

float boxIou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const float inter = (a & b).area();
  const float uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.f;
}

// Some ground-truth person box containing p overlaps no screened box by kDetectedIou.
bool nearUndetectedPerson(const detection::Boxes& truth, const detection::Boxes& boxes, cv::Point2f p,
                          float detected_iou) {
  for (const auto& t : truth) {
    if (!t.rect.contains(p)) continue;
    bool found = false;
    for (const auto& b : boxes) found = found || boxIou(t.rect, b.rect) >= detected_iou;
    if (!found) return true;
  }
  return false;
}

// Median depth of the keypoints with depth dropped inside r (0 if none).
float droppedDepth(const features::FeatureFrame& f, const cv::Rect2f& r) {
  std::vector<float> d;
  for (size_t i = 0; i < f.keypoints.size(); ++i)
    if (f.dynamic[i] && f.depth[i] > 0 && inside(r, f.keypoints[i].pt)) d.push_back(f.depth[i]);
  if (d.empty()) return 0.f;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

// In a box with depth, the keypoint is compared with the box (of those containing it) whose
// dropped median depth is nearest to its own.
void countMisses(const features::FeatureFrame& f, const cv::Mat& mask, const detection::Boxes& boxes,
                 const detection::Boxes& truth, const ScreeningOptions& o, float detected_iou, Misses& m) {
  std::vector<cv::Rect2f> rects;
  std::vector<float> dropped_at;
  for (const auto& b : boxes) {
    rects.push_back(dilate(b.rect, o.box_dilation));
    dropped_at.push_back(droppedDepth(f, rects.back()));
  }
  for (size_t i = 0; i < f.keypoints.size(); ++i) {
    const cv::Point2f p = f.keypoints[i].pt;
    const int x = std::min(mask.cols - 1, std::max(0, static_cast<int>(std::lround(p.x))));
    const int y = std::min(mask.rows - 1, std::max(0, static_cast<int>(std::lround(p.y))));
    if (mask.at<uint8_t>(y, x) != 255 || f.dynamic[i]) continue;
    const float d = f.depth[i];
    int box = -1;
    for (size_t b = 0; b < rects.size(); ++b)
      if (inside(rects[b], p) &&
          (box < 0 || std::abs(dropped_at[b] - d) < std::abs(dropped_at[box] - d)))
        box = static_cast<int>(b);
    if (box < 0) {
      ++(d > 0 ? m.outside_depth : m.outside_hole);
    } else if (d <= 0) {
      ++m.in_box_hole;
    } else if (dropped_at[box] <= 0) {
      ++m.box_dropped_nothing;
    } else {
      const double gap = d - dropped_at[box];
      if (gap < -o.grow_depth_m) ++m.nearer;
      else if (gap <= o.grow_depth_m) ++m.within;
      else ++(gap <= kBehindM ? m.behind : m.far_behind);
      if (gap > kBehindM && nearUndetectedPerson(truth, boxes, p, detected_iou)) ++m.far_behind_unboxed;
    }
  }
}

// Distance buckets (pixels to the nearest dynamic mask pixel) of the static keypoints dropped.
const std::vector<double> kBuckets = {2, 5, 10, 20, 40, 1e9};

void distances(const features::FeatureFrame& f, const cv::Mat& mask, std::vector<long>& hist,
               std::vector<long>& hist_hole) {
  cv::Mat background = mask <= 127, dist;
  cv::distanceTransform(background, dist, cv::DIST_L2, 3);
  for (size_t i = 0; i < f.keypoints.size(); ++i) {
    const cv::Point2f p = f.keypoints[i].pt;
    const int x = std::min(mask.cols - 1, std::max(0, static_cast<int>(std::lround(p.x))));
    const int y = std::min(mask.rows - 1, std::max(0, static_cast<int>(std::lround(p.y))));
    if (mask.at<uint8_t>(y, x) > 127 || !f.dynamic[i]) continue;
    const float d = dist.at<float>(y, x);
    size_t k = 0;
    while (d > kBuckets[k]) ++k;
    ++(f.depth[i] > 0 ? hist : hist_hole)[k];
  }
}

void run(const std::string& dir, const std::string& run_dir, int stride, int max_frames,
         const std::vector<std::string>& sets, float detected_iou) {
  Config cfg = Config::fromFile(joinPath(dir, "camera.yaml"));
  for (const auto& s : sets) cfg.setFromAssignment(s);
  const ScreeningOptions base = ScreeningOptions::load(cfg);
  CameraModel cam = CameraModel::load(cfg);
  cam.rgb_order = false;  // cv::imread gives BGR
  features::OrbExtractor orb{features::OrbOptions::load(cfg)};
  const auto boxes_of = readScreenedBoxes(joinPath(run_dir, "boxes_screened.txt"));
  const auto truth_of = bench::readPersonBoxes(joinPath(dir, "boxes.txt"));
  const std::vector<Variant> vs = variants();
  std::vector<Split> split(vs.size());
  std::vector<long> hist(kBuckets.size(), 0), hist_hole(kBuckets.size(), 0);
  Misses misses;
  std::ifstream assoc(joinPath(dir, "associations.txt"));
  if (!assoc) throw Error(joinPath(dir, "associations.txt") + ": not found");
  std::string line;
  int idx = 0, used = 0;
  while (std::getline(assoc, line) && idx < max_frames) {
    if (line.empty() || line[0] == '#') continue;
    if (idx++ % stride) continue;
    std::istringstream is(line);
    std::string rgb_stamp, rgb_rel, depth_stamp, depth_rel;
    if (!(is >> rgb_stamp >> rgb_rel >> depth_stamp >> depth_rel)) continue;
    const cv::Mat bgr = cv::imread(joinPath(dir, rgb_rel), cv::IMREAD_COLOR);
    const cv::Mat raw = cv::imread(joinPath(dir, depth_rel), cv::IMREAD_ANYDEPTH);
    if (bgr.empty() || raw.empty()) throw Error(joinPath(dir, rgb_rel) + ": missing frame");
    cv::Mat depth_m;
    raw.convertTo(depth_m, CV_32F, 1.0 / cam.depth_map_factor);
    const std::string name = rgb_rel.substr(rgb_rel.find_last_of('/') + 1);
    const cv::Mat mask = loadMask(joinPath(dir, "masks/" + name));
    const features::FeatureFrame frame = features::buildFeatureFrame(orb, cam, bgr, depth_m, 0.0);
    const auto it = boxes_of.find(rgb_stamp);
    const detection::Boxes boxes = it == boxes_of.end() ? detection::Boxes() : it->second;
    for (size_t k = 0; k < vs.size(); ++k) {
      ScreeningOptions o = base;
      vs[k].change(o);
      features::FeatureFrame f = frame;
      Screener(o).screen(f, boxes, depth_m);
      count(f, mask, boxes, o.box_dilation, split[k]);
      if (k == 0) {
        distances(f, mask, hist, hist_hole);
        const auto t = truth_of.find(bench::stampKey(std::stod(rgb_stamp)));
        countMisses(f, mask, boxes, t == truth_of.end() ? detection::Boxes() : t->second, o, detected_iou, misses);
      }
    }
    ++used;
  }
  std::printf("%s, boxes of %s: %d frames (every %d)\n\n", dir.c_str(), run_dir.c_str(), used, stride);
  std::printf("| configuration | static dropped | in box, depth | in box, no depth | outside, depth | "
              "outside, no depth | person recall |\n|---|---|---|---|---|---|---|\n");
  for (size_t k = 0; k < vs.size(); ++k) {
    const Split& s = split[k];
    std::printf("| %s | %ld (%.1f %%) | %ld | %ld | %ld | %ld | %.1f %% |\n", vs[k].name.c_str(),
                s.static_dropped, 100.0 * s.static_dropped / std::max(1L, s.static_total),
                s.in_box_depth, s.in_box_hole, s.outside_depth, s.outside_hole,
                100.0 * s.person_dropped / std::max(1L, s.person_total));
  }
  std::printf("\nstatic keypoints dropped by the configuration, by distance to the nearest dynamic "
              "pixel:\n| up to (px) | with depth | without depth |\n|---|---|---|\n");
  for (size_t k = 0; k < kBuckets.size(); ++k)
    std::printf("| %s | %ld | %ld |\n", kBuckets[k] > 1e8 ? "more" : std::to_string(int(kBuckets[k])).c_str(),
                hist[k], hist_hole[k]);
  std::printf("\nperson keypoints the configuration leaves static (in a box with depth: against "
              "the median depth the box dropped, +- growDepth):\n"
              "| outside every box, depth | outside, no depth | in a box, no depth | box dropped "
              "nothing | nearer | within | behind, up to %.1f m | more than %.1f m behind |\n"
              "|---|---|---|---|---|---|---|---|\n| %ld | %ld | %ld | %ld | %ld | %ld | %ld | %ld |\n",
              kBehindM, kBehindM, misses.outside_depth, misses.outside_hole, misses.in_box_hole,
              misses.box_dropped_nothing, misses.nearer, misses.within, misses.behind,
              misses.far_behind);
  std::printf("\nof the %ld more than %.1f m behind, %ld lie in the ground-truth box of a person no "
              "screened box overlaps by IoU %.2f (missed, or boxed loosely at that IoU)\n",
              misses.far_behind, kBehindM, misses.far_behind_unboxed, detected_iou);
}

}  // namespace

int main(int argc, char** argv) {
  std::string sequence, run_dir;
  int stride = 5, max_frames = 1 << 30;
  float detected_iou = kDefaultDetectedIou;
  std::vector<std::string> sets;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw Error(a + " needs a value");
        return argv[++i];
      };
      if (a == "--sequence") sequence = next();
      else if (a == "--run") run_dir = next();
      else if (a == "--stride") stride = std::max(1, std::stoi(next()));
      else if (a == "--max-frames") max_frames = std::stoi(next());
      else if (a == "--set") sets.push_back(next());
      else if (a == "--detected-iou") detected_iou = std::stof(next());
      else if (a == "--help" || a == "-h") {
        std::printf("usage: screening_rules --sequence SEQ --run RUN [--stride N] [--max-frames N] "
                    "[--set KEY=VALUE]... [--detected-iou X]\n");
        return 0;
      } else throw Error("unknown option " + a + " (see --help)");
    }
    if (sequence.empty() || run_dir.empty()) throw Error("--sequence and --run are required (see --help)");
    run(sequence, run_dir, stride, max_frames, sets, detected_iou);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
