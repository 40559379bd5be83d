// Screening benchmark on the real TUM fr3_walking_xyz frame with its person mask (shared data):
//   screening_bench [--reps N] [--detector] [--sweep] [--variants] [--seeds S] [--border PX]
//   screening_bench --sequence DIR [--stride N] [--detector]
// --sequence: quality of several configurations over every N-th frame of a yolo_slam_synth
// sequence (exact masks/, boxes from boxes.txt or from the detector).
// Prints the time per frame of Screener::screen for each mode and variant (median over N
// repetitions) and the quality against the mask: dynamic recall (mask keypoints dropped) and
// static retention (non-mask keypoints inside boxes kept). --sweep prints the nThre table of
// docs/screening.md (interpretations of the paper's 0.43 and a threshold sweep), averaged over
// S seeds; --variants prints only the table of beyond-paper configurations (nearest cluster,
// no-depth rules, dilation) and exits. Boxes come from the mask's connected components, or from the YOLO detector with
// --detector (default model, see detection/detector.h). --flat: the flat-box rule
// (screening/flat_box.h): per-box test numbers on the real frame, or the defaults without and
// with the rule over a tolerance x fraction grid on a --sequence (with --verbose, every box).
// --help lists the options.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/screening/flat_box.h"
#include "yolo_slam/screening/screener.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace yolo_slam;
using namespace yolo_slam::screening;

namespace {

struct RealFrame {
  features::FeatureFrame frame;
  cv::Mat mask;
  detection::Boxes boxes;
};

detection::Boxes boxesFromMask(const cv::Mat& mask) {
  cv::Mat labels, stats, centroids;
  int n = cv::connectedComponentsWithStats(mask > 127, labels, stats, centroids);
  detection::Boxes boxes;
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) < 2000) continue;  // specks are not people
    detection::Box b;
    b.class_id = 14;
    b.label = "person";
    b.score = 1.f;
    b.rect = cv::Rect2f(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                        stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT));
    boxes.push_back(b);
  }
  return boxes;
}

RealFrame loadRealFrame(bool use_detector) {
  const std::string dir = joinPath(sharedDir(), "data/tum/rgbd_dataset_freiburg3_walking_xyz");
  const std::string rgb_path = joinPath(dir, "rgb/1341846313.592026.png");
  const std::string depth_path = joinPath(dir, "depth/1341846313.592088.png");
  const std::string mask_path = joinPath(dir, "dynamic_mask/1341846313.592026.png");
  cv::Mat bgr = cv::imread(rgb_path, cv::IMREAD_COLOR);
  if (bgr.empty()) throw Error(rgb_path + ": missing or unreadable; set YOLO_SLAM_SHARED to the shared folder");
  cv::Mat raw = cv::imread(depth_path, cv::IMREAD_ANYDEPTH);
  if (raw.empty() || raw.type() != CV_16UC1)
    throw Error(depth_path + ": missing or not a 16-bit depth PNG; set YOLO_SLAM_SHARED to the shared folder");
  cv::Mat depth_m;
  raw.convertTo(depth_m, CV_32F, 1.0 / 5000.0);  // TUM: metres x 5000, 0 = no depth

  RealFrame rf;
  rf.mask = loadMask(mask_path);
  CameraModel cam;      // TUM fr3 defaults: no distortion
  cam.rgb_order = false;  // cv::imread gives BGR
  features::OrbExtractor orb{features::OrbOptions{}};
  rf.frame = features::buildFeatureFrame(orb, cam, bgr, depth_m, 1341846313.592026);
  if (use_detector) {
    rf.boxes = detection::makeDetector(detection::DetectorOptions{})->detect(bgr);
  } else {
    rf.boxes = boxesFromMask(rf.mask);
  }
  return rf;
}

struct Quality {
  double recall = 0, retention = 0, dropped = 0;
};

// Configurations compared on both the real frame and synthetic sequences (docs/screening.md,
// "nearest cluster"). Defaults of ScreeningOptions apart from what each entry sets.
struct NamedOptions {
  std::string name;
  ScreeningOptions o;
};

std::vector<NamedOptions> variantConfigs() {
  using NDR = ScreeningOptions::NoDepthRule;
  std::vector<NamedOptions> v;
  auto add = [&](const std::string& name, ScreeningVariant var, double thr, NDR nd, double dil,
                 bool depth_only, double frac = 0.3, double nd_radius = 20) {
    ScreeningOptions o;
    o.variant = var;
    o.variance_threshold_m2 = thr;
    o.no_depth = nd;
    o.box_dilation = dil;
    o.dilation_depth_only = depth_only;
    o.cluster_min_fraction = frac;
    o.no_depth_radius_px = nd_radius;
    v.push_back({name, o});
  };
  add("paper 0.02 (old variant)", ScreeningVariant::Paper, 0.02, NDR::Dynamic, 0.05, false);
  add("grow 0.02 dyn dil 0.05 (old default)", ScreeningVariant::Grow, 0.02, NDR::Dynamic, 0.05, false);
  add("grow 0.02 near-dyn 20", ScreeningVariant::Grow, 0.02, NDR::NearDynamic, 0.05, false);
  add("grow 0.02 dyn depth-only dil", ScreeningVariant::Grow, 0.02, NDR::Dynamic, 0.05, true);
  add("grow 0.02 near-dyn 20 depth-only dil", ScreeningVariant::Grow, 0.02, NDR::NearDynamic, 0.05, true);
  for (double thr : {0.02, 0.05}) {
    for (double frac : {0.2, 0.3, 0.5}) {
      for (NDR nd : {NDR::Dynamic, NDR::NearDynamic}) {
        for (bool depth_only : {false, true}) {
          char buf[160];
          std::snprintf(buf, sizeof buf, "nearest %.2f frac %.1f %s%s", thr, frac,
                        nd == NDR::Dynamic ? "dyn" : "near-dyn 20",
                        depth_only ? " depth-only dil" : "");
          add(buf, ScreeningVariant::Nearest, thr, nd, 0.05, depth_only, frac);
        }
      }
    }
  }
  for (double r : {10.0, 30.0, 40.0, 60.0})
    for (double dil : {0.05, 0.1}) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "nearest 0.02 frac 0.3 near-dyn %.0f depth-only dil %.2f", r, dil);
      add(buf, ScreeningVariant::Nearest, 0.02, NDR::NearDynamic, dil, true, 0.3, r);
    }
  add("nearest 0.02 frac 0.3 near-dyn 40 dil 0.05", ScreeningVariant::Nearest, 0.02,
      NDR::NearDynamic, 0.05, false, 0.3, 40);
  add("nearest 0.02 frac 0.3 near-dyn 40 no dilation", ScreeningVariant::Nearest, 0.02,
      NDR::NearDynamic, 0.0, false, 0.3, 40);
  return v;
}

int g_border = 0;  // --border: pixels of the mask boundary left out of the metrics

Quality quality(const RealFrame& rf, ScreeningOptions o, int seeds) {
  Quality q;
  for (int s = 0; s < seeds; ++s) {
    o.seed = static_cast<unsigned>(s);
    features::FeatureFrame f = rf.frame;
    ScreeningStats st = Screener(o).screen(f, rf.boxes);
    ScreeningMetrics m = evaluateScreening(f, rf.mask, rf.boxes, g_border);
    q.recall += m.dynamicRecall() / seeds;
    q.retention += m.staticRetention() / seeds;
    q.dropped += static_cast<double>(st.dropped) / seeds;
  }
  return q;
}

void printCounts(const RealFrame& rf) {
  int in_box = 0, on_mask = 0, on_mask_in_box = 0, static_in_box = 0, nodepth_mask = 0,
      nodepth_static = 0;
  for (size_t i = 0; i < rf.frame.size(); ++i) {
    const cv::Point2f p = rf.frame.keypoints[i].pt;
    bool ib = false;
    for (const auto& b : rf.boxes) ib = ib || b.rect.contains(p);
    const bool gt = rf.mask.at<uint8_t>(cvRound(std::min(p.y, 479.f)), cvRound(std::min(p.x, 639.f))) > 127;
    in_box += ib;
    on_mask += gt;
    on_mask_in_box += gt && ib;
    static_in_box += !gt && ib;
    if (ib && rf.frame.depth[i] <= 0) (gt ? nodepth_mask : nodepth_static)++;
  }
  std::printf("keypoints %zu, in boxes %d, on mask %d (in boxes %d), static in boxes %d\n",
              rf.frame.size(), in_box, on_mask, on_mask_in_box, static_in_box);
  std::printf("in-box keypoints without depth: %d on the mask, %d static\n", nodepth_mask,
              nodepth_static);
  for (const auto& b : rf.boxes)
    std::printf("box %s %.2f [%.0f %.0f %.0f x %.0f]\n", b.label.c_str(), b.score, b.rect.x,
                b.rect.y, b.rect.width, b.rect.height);
}

void sweep(const RealFrame& rf, int seeds) {
  struct Interp {
    const char* name;
    double var_m2;
  };
  const double t = 0.43;
  const Interp interps[] = {
      {"variance in m^2", t},
      {"std in m (var = 0.43^2 m^2)", t * t},
      {"variance in dm^2", t * 1e-2},
      {"std in dm", (t * 0.1) * (t * 0.1)},
      {"variance in cm^2", t * 1e-4},
      {"std in cm", (t * 0.01) * (t * 0.01)},
      {"variance in mm^2", t * 1e-6},
      {"variance in TUM raw units (1/5000 m)^2", t / 25e6},
  };
  std::printf("\n| nThre = 0.43 read as | threshold (m^2) | variant | noDepth | dynamic recall | static kept in boxes | dropped |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const auto& in : interps) {
    for (ScreeningVariant v : {ScreeningVariant::Paper, ScreeningVariant::Grow}) {
      ScreeningOptions o;
      o.variant = v;
      o.variance_threshold_m2 = in.var_m2;
      Quality q = quality(rf, o, seeds);
      std::printf("| %s | %.3g | %s | dynamic | %.3f | %.3f | %.1f |\n", in.name, in.var_m2,
                  toString(v).c_str(), q.recall, q.retention, q.dropped);
    }
  }
  std::printf("\n| threshold (m^2) | variant | noDepth | grow radius px | grow depth m | dynamic recall | static kept in boxes | dropped |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  using NDR = ScreeningOptions::NoDepthRule;
  const char* nd_names[] = {"dynamic", "static", "nearest"};
  for (double thr : {0.001, 0.005, 0.01, 0.02, 0.05, 0.1, 0.185, 0.43}) {
    for (NDR nd : {NDR::Dynamic, NDR::Static, NDR::Nearest}) {
      ScreeningOptions o;
      o.variant = ScreeningVariant::Paper;
      o.variance_threshold_m2 = thr;
      o.no_depth = nd;
      Quality q = quality(rf, o, seeds);
      std::printf("| %.3g | paper | %s | - | - | %.3f | %.3f | %.1f |\n", thr,
                  nd_names[static_cast<int>(nd)], q.recall, q.retention, q.dropped);
      o.variant = ScreeningVariant::Grow;
      for (double radius : {30.0, 50.0}) {
        for (double gd : {0.1}) {
          o.grow_radius_px = radius;
          o.grow_depth_m = gd;
          q = quality(rf, o, seeds);
          std::printf("| %.3g | grow | %s | %.0f | %.2f | %.3f | %.3f | %.1f |\n", thr,
                      nd_names[static_cast<int>(nd)], radius, gd, q.recall, q.retention, q.dropped);
        }
      }
    }
  }
  std::printf("\n| defaults with box dilation | dynamic recall | static kept in boxes | dropped |\n|---|---|---|---|\n");
  for (double dil : {0.0, 0.05, 0.1, 0.2}) {
    ScreeningOptions o;
    o.box_dilation = dil;
    Quality q = quality(rf, o, seeds);
    std::printf("| %.2f | %.3f | %.3f | %.1f |\n", dil, q.recall, q.retention, q.dropped);
  }
  ScreeningOptions d;
  d.mode = DynamicMode::Detect;
  Quality qd = quality(rf, d, 1);
  std::printf("| (mode detect) | - | - | 0 | %.3f | %.3f | %.1f |\n", qd.recall, qd.retention, qd.dropped);
  d.mode = DynamicMode::Geometry;
  Quality qg = quality(rf, d, seeds);
  std::printf("| (mode geometry, default threshold) | - | - | - | %.3f | %.3f | %.1f |\n", qg.recall,
              qg.retention, qg.dropped);
}

void variantsTable(const RealFrame& rf, int seeds) {
  std::printf("\n| configuration (dilation 0.05 unless named) | dynamic recall | static kept in boxes | dropped |\n|---|---|---|---|\n");
  for (const auto& c : variantConfigs()) {
    Quality q = quality(rf, c.o, seeds);
    std::printf("| %s | %.3f | %.3f | %.1f |\n", c.name.c_str(), q.recall, q.retention, q.dropped);
  }
}

void timing(const RealFrame& rf, int reps) {
  std::printf("\n| mode | variant | in boxes | dropped | iterations | median ms | p95 ms |\n|---|---|---|---|---|---|---|\n");
  for (DynamicMode m : {DynamicMode::Detect, DynamicMode::Geometry, DynamicMode::DetectGeometry}) {
    for (ScreeningVariant v : {ScreeningVariant::Paper, ScreeningVariant::Grow, ScreeningVariant::Nearest}) {
      if (m == DynamicMode::Detect && v != ScreeningVariant::Paper) continue;
      ScreeningOptions o;
      o.mode = m;
      o.variant = v;
      Screener scr(o);
      std::vector<double> ms;
      ScreeningStats st;
      for (int r = 0; r < reps; ++r) {
        features::FeatureFrame f = rf.frame;
        Stopwatch sw;
        st = scr.screen(f, rf.boxes);
        ms.push_back(sw.ms());
      }
      Summary s = summarize(ms);
      std::printf("| %s | %s | %d | %d | %d | %.4f | %.4f |\n", toString(m).c_str(),
                  m == DynamicMode::Detect ? "-" : toString(v).c_str(), st.in_boxes, st.dropped,
                  st.iterations, s.median, s.p95);
    }
  }
}

// The flat-box test's numbers for one box under the defaults with the rule on: the cluster is
// what the screener drops in this box alone without the rule.
void printFlatNumbers(const features::FeatureFrame& frame, const detection::Box& b,
                      const detection::Boxes& all) {
  ScreeningOptions o;
  features::FeatureFrame f = frame;
  Screener(o).screen(f, {b});
  std::vector<int> cluster;
  for (size_t i = 0; i < f.size(); ++i)
    if (f.dynamic[i]) cluster.push_back(static_cast<int>(i));
  const float dx = b.rect.width * o.box_dilation, dy = b.rect.height * o.box_dilation;
  const cv::Rect2f r(b.rect.x - dx, b.rect.y - dy, b.rect.width + 2 * dx, b.rect.height + 2 * dy);
  FlatBoxOptions fo;
  fo.ring = o.flat_box_ring;
  fo.tolerance = o.flat_box_tolerance;
  fo.fraction = o.flat_box_fraction;
  std::vector<cv::Rect2f> others;
  for (const auto& x : all) {
    if (&x == &b) continue;
    const float ex = x.rect.width * o.box_dilation, ey = x.rect.height * o.box_dilation;
    others.emplace_back(x.rect.x - ex, x.rect.y - ey, x.rect.width + 2 * ex, x.rect.height + 2 * ey);
  }
  FlatBoxResult res = testFlatBox(frame, r, cluster, fo, others);
  std::printf("| [%.0f %.0f %.0f x %.0f] | %d (%d) | %d (%d) | %.3f | %s |\n", b.rect.x, b.rect.y,
              b.rect.width, b.rect.height, res.cluster_points, res.cluster_inliers,
              res.ring_points, res.ring_on_plane, res.ringFraction(), res.flat ? "yes" : "no");
}

// A synthetic sequence of yolo_slam_synth: associations.txt, masks/<rgb name>.png and
// boxes.txt ("rgb_stamp id class x1 y1 x2 y2 visible_fraction", x2/y2 exclusive).
void sequenceSweep(const std::string& dir, int stride, bool use_detector, bool flat, bool verbose) {
  std::ifstream assoc(joinPath(dir, "associations.txt"));
  if (!assoc) throw Error(joinPath(dir, "associations.txt") + ": not found; pass a yolo_slam_synth output folder");
  std::map<std::string, detection::Boxes> gt_boxes;
  {
    const std::string path = joinPath(dir, "boxes.txt");
    std::ifstream in(path);
    if (!in) throw Error(path + ": not found; --sequence needs a synthetic sequence with boxes.txt");
    std::string line;
    int ln = 0;
    while (std::getline(in, line)) {
      ++ln;
      if (line.empty() || line[0] == '#') continue;
      std::istringstream is(line);
      std::string stamp, cls;
      int id;
      float x1, y1, x2, y2, vis;
      if (!(is >> stamp >> id >> cls >> x1 >> y1 >> x2 >> y2 >> vis))
        throw Error(path + ":" + std::to_string(ln) + ": malformed line; expected 'stamp id class x1 y1 x2 y2 visible'");
      detection::Box b;
      b.label = cls;
      b.score = 1.f;
      b.rect = cv::Rect2f(x1, y1, x2 - x1, y2 - y1);
      gt_boxes[stamp].push_back(b);
    }
  }
  struct Cfg {
    std::string name;
    ScreeningOptions o;
  };
  std::vector<Cfg> cfgs;
  auto add = [&](const std::string& name, ScreeningVariant v, double thr,
                 ScreeningOptions::NoDepthRule nd, double dil = 0.0) {
    ScreeningOptions o;
    o.variant = v;
    o.variance_threshold_m2 = thr;
    o.no_depth = nd;
    o.box_dilation = dil;
    cfgs.push_back({name, o});
  };
  using NDR = ScreeningOptions::NoDepthRule;
  add("paper 0.43 m^2", ScreeningVariant::Paper, 0.43, NDR::Dynamic);
  add("paper 0.185 m^2 (0.43 m std)", ScreeningVariant::Paper, 0.185, NDR::Dynamic);
  add("paper 0.1", ScreeningVariant::Paper, 0.1, NDR::Dynamic);
  add("paper 0.02", ScreeningVariant::Paper, 0.02, NDR::Dynamic);
  add("paper 0.0043 (0.43 dm^2)", ScreeningVariant::Paper, 0.0043, NDR::Dynamic);
  add("grow 0.1", ScreeningVariant::Grow, 0.1, NDR::Dynamic);
  add("grow 0.05", ScreeningVariant::Grow, 0.05, NDR::Dynamic);
  add("grow 0.02", ScreeningVariant::Grow, 0.02, NDR::Dynamic);
  add("grow 0.02 noDepth static", ScreeningVariant::Grow, 0.02, NDR::Static);
  add("grow 0.02 noDepth nearest", ScreeningVariant::Grow, 0.02, NDR::Nearest);
  add("grow 0.02 dilation 0.05 (default)", ScreeningVariant::Grow, 0.02, NDR::Dynamic, 0.05);
  add("grow 0.005", ScreeningVariant::Grow, 0.005, NDR::Dynamic);
  add("paper 0.02 noDepth nearest", ScreeningVariant::Paper, 0.02, NDR::Nearest);
  add("grow 0.05 noDepth nearest", ScreeningVariant::Grow, 0.05, NDR::Nearest);
  add("grow 0.1 noDepth nearest", ScreeningVariant::Grow, 0.1, NDR::Nearest);
  add("paper 0.43 noDepth nearest", ScreeningVariant::Paper, 0.43, NDR::Nearest);
  for (const auto& c : variantConfigs()) cfgs.push_back({c.name, c.o});
  if (flat) {
    // --flat: the defaults without and with the flat-box rule over a small grid.
    cfgs.clear();
    cfgs.push_back({"defaults (flat-box rule off)", ScreeningOptions{}});
    for (double tol : {0.005, 0.01, 0.02})
      for (double frac : {0.3, 0.4, 0.5}) {
        ScreeningOptions o;
        o.reject_flat_boxes = true;
        o.flat_box_tolerance = tol;
        o.flat_box_fraction = frac;
        char name[96];
        std::snprintf(name, sizeof name, "flat-box tol %.3f 1/m, fraction %.2f", tol, frac);
        cfgs.push_back({name, o});
      }
  }
  std::vector<ScreeningMetrics> total(cfgs.size());
  std::vector<int> flat_boxes(cfgs.size(), 0);
  int n_boxes = 0;
  ScreeningMetrics det_total;

  CameraModel cam = CameraModel::load(Config::fromFile(joinPath(dir, "camera.yaml")));
  features::OrbExtractor orb{features::OrbOptions{}};
  std::unique_ptr<detection::Detector> det;
  if (use_detector) det = detection::makeDetector(detection::DetectorOptions{});
  std::string line;
  int idx = 0, used = 0;
  while (std::getline(assoc, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (idx++ % stride) continue;
    std::istringstream is(line);
    std::string rgb_stamp, rgb_rel, depth_stamp, depth_rel;
    if (!(is >> rgb_stamp >> rgb_rel >> depth_stamp >> depth_rel)) continue;
    cv::Mat bgr = cv::imread(joinPath(dir, rgb_rel), cv::IMREAD_COLOR);
    cv::Mat raw = cv::imread(joinPath(dir, depth_rel), cv::IMREAD_ANYDEPTH);
    if (bgr.empty() || raw.empty()) throw Error(joinPath(dir, rgb_rel) + ": missing or unreadable frame");
    cv::Mat depth_m;
    raw.convertTo(depth_m, CV_32F, 1.0 / cam.depth_map_factor);
    const std::string name = rgb_rel.substr(rgb_rel.find_last_of('/') + 1);
    cv::Mat mask = loadMask(joinPath(dir, "masks/" + name));
    CameraModel c = cam;
    c.rgb_order = false;  // cv::imread gives BGR
    features::FeatureFrame frame = features::buildFeatureFrame(orb, c, bgr, depth_m, 0.0);
    detection::Boxes boxes = det ? det->detect(bgr) : gt_boxes[rgb_stamp];
    if (verbose) {
      // Each box's best IoU with a ground-truth person box: flat boxes with IoU >= 0.3 are
      // real people the rule would leave undropped.
      for (const auto& b : boxes) {
        double iou = 0;
        for (const auto& g : gt_boxes[rgb_stamp]) {
          const double inter = (b.rect & g.rect).area();
          iou = std::max(iou, inter / (b.rect.area() + g.rect.area() - inter));
        }
        std::printf("%s score %.2f iou %.2f ", rgb_stamp.c_str(), b.score, iou);
        printFlatNumbers(frame, b, boxes);
      }
    }
    for (size_t k = 0; k < cfgs.size(); ++k) {
      features::FeatureFrame f = frame;
      flat_boxes[k] += Screener(cfgs[k].o).screen(f, boxes).flat_boxes;
      total[k] += evaluateScreening(f, mask, boxes);
    }
    ScreeningOptions d;
    d.mode = DynamicMode::Detect;
    features::FeatureFrame f = frame;
    Screener(d).screen(f, boxes);
    det_total += evaluateScreening(f, mask, boxes);
    n_boxes += static_cast<int>(boxes.size());
    ++used;
  }
  std::printf("\n%s: %d frames (every %d), %s boxes\n", dir.c_str(), used, stride,
              use_detector ? "detector" : "ground-truth");
  std::printf("| configuration | dynamic keypoints | dynamic recall | static in boxes | static kept in boxes | flat boxes / boxes |\n|---|---|---|---|---|---|\n");
  for (size_t k = 0; k < cfgs.size(); ++k)
    std::printf("| %s | %d | %.3f | %d | %.3f | %d / %d |\n", cfgs[k].name.c_str(),
                total[k].dynamic_total, total[k].dynamicRecall(), total[k].static_in_boxes,
                total[k].staticRetention(), flat_boxes[k], n_boxes);
  std::printf("| mode detect | %d | %.3f | %d | %.3f | - |\n", det_total.dynamic_total,
              det_total.dynamicRecall(), det_total.static_in_boxes, det_total.staticRetention());
}

// --flat on the real frame: the flat-box test's numbers for each box (defaults otherwise).
void realFlat(const RealFrame& rf) {
  std::printf("\n| box | cluster kp (on plane) | ring kp (on cluster plane) | ring fraction | flat |\n|---|---|---|---|---|\n");
  for (const auto& b : rf.boxes) printFlatNumbers(rf.frame, b, rf.boxes);
}

constexpr const char* kUsage =
    "usage: screening_bench [--reps N] [--seeds S] [--detector] [--sweep] [--variants] [--flat]\n"
    "                       [--border PX]\n"
    "       screening_bench --sequence DIR [--stride N] [--detector] [--flat] [--verbose]\n"
    "Screening quality and timing on the real TUM fr3_walking_xyz frame (shared data), or over a\n"
    "yolo_slam_synth sequence.\n"
    "  --reps N      timing repetitions per configuration (200)\n"
    "  --seeds S     RANSAC seeds averaged in --sweep/--variants (20)\n"
    "  --detector    boxes from the YOLO detector instead of the mask / boxes.txt\n"
    "  --sweep       nThre interpretation and threshold table\n"
    "  --variants    beyond-paper configuration table only, then exit\n"
    "  --flat        flat-box rule: per-box test numbers (real frame) or on/off grid (--sequence)\n"
    "  --border PX   leave out keypoints within PX of the mask boundary (0)\n"
    "  --sequence D  synthetic sequence folder (associations.txt, masks/, boxes.txt)\n"
    "  --stride N    every N-th frame of the sequence (10)\n"
    "  --verbose     --sequence: the flat-box test's numbers for every box (stamp, box, cluster\n"
    "                keypoints on its plane, ring keypoints on that plane)\n"
    "  -h, --help    this text\n";

}  // namespace

int main(int argc, char** argv) {
  try {
    int reps = 200, seeds = 20;
    bool use_detector = false, do_sweep = false, do_variants = false, do_flat = false,
         verbose = false;
    std::string sequence;
    int stride = 10;
    for (int i = 1; i < argc; ++i) {
      std::string a = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw Error("option " + a + " needs a value");
        return argv[++i];
      };
      if (a == "-h" || a == "--help") {
        std::fputs(kUsage, stdout);
        return 0;
      }
      if (a == "--reps") reps = std::stoi(next());
      else if (a == "--flat") do_flat = true;
      else if (a == "--verbose") verbose = true;
      else if (a == "--seeds") seeds = std::stoi(next());
      else if (a == "--detector") use_detector = true;
      else if (a == "--sweep") do_sweep = true;
      else if (a == "--variants") do_variants = true;
      else if (a == "--border") g_border = std::stoi(next());
      else if (a == "--sequence") sequence = next();
      else if (a == "--stride") stride = std::stoi(next());
      else throw Error("unknown option '" + a + "'; see screening_bench --help");
    }
    if (reps < 1 || seeds < 1 || stride < 1) throw Error("--reps, --seeds and --stride must be >= 1");
    if (!sequence.empty()) {
      sequenceSweep(sequence, stride, use_detector, do_flat, verbose);
      return 0;
    }
    RealFrame rf = loadRealFrame(use_detector);
    printCounts(rf);
    if (do_flat) {
      realFlat(rf);
      return 0;
    }
    if (do_sweep) sweep(rf, seeds);
    if (do_sweep || do_variants) variantsTable(rf, seeds);
    if (do_variants) return 0;
    timing(rf, reps);
  } catch (const Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
