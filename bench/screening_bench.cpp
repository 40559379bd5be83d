// Screening benchmark on the real TUM fr3_walking_xyz frame with its person mask (shared data):
//   screening_bench [--reps N] [--detector] [--sweep] [--seeds S] [--border PX]
// Prints the time per frame of Screener::screen for each mode and variant (median over N
// repetitions) and the quality against the mask: dynamic recall (mask keypoints dropped) and
// static retention (non-mask keypoints inside boxes kept). --sweep prints the nThre table of
// docs/screening.md (interpretations of the paper's 0.43 and a threshold sweep), averaged over
// S seeds. Boxes come from the mask's connected components, or from the YOLO detector with
// --detector (default model, see detection/detector.h).
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/screening/screener.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <cstring>
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
    detection::YoloDetector det{detection::DetectorOptions{}};
    rf.boxes = det.detect(bgr);
  } else {
    rf.boxes = boxesFromMask(rf.mask);
  }
  return rf;
}

struct Quality {
  double recall = 0, retention = 0, dropped = 0;
};

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
  ScreeningOptions d;
  d.mode = DynamicMode::Detect;
  Quality qd = quality(rf, d, 1);
  std::printf("| (mode detect) | - | - | 0 | %.3f | %.3f | %.1f |\n", qd.recall, qd.retention, qd.dropped);
  d.mode = DynamicMode::Geometry;
  Quality qg = quality(rf, d, seeds);
  std::printf("| (mode geometry, default threshold) | - | - | - | %.3f | %.3f | %.1f |\n", qg.recall,
              qg.retention, qg.dropped);
}

void timing(const RealFrame& rf, int reps) {
  std::printf("\n| mode | variant | in boxes | dropped | iterations | median ms | p95 ms |\n|---|---|---|---|---|---|---|\n");
  for (DynamicMode m : {DynamicMode::Detect, DynamicMode::Geometry, DynamicMode::DetectGeometry}) {
    for (ScreeningVariant v : {ScreeningVariant::Paper, ScreeningVariant::Grow}) {
      if (m == DynamicMode::Detect && v == ScreeningVariant::Grow) continue;
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

}  // namespace

int main(int argc, char** argv) {
  try {
    int reps = 200, seeds = 20;
    bool use_detector = false, do_sweep = false;
    for (int i = 1; i < argc; ++i) {
      std::string a = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw Error("option " + a + " needs a value");
        return argv[++i];
      };
      if (a == "--reps") reps = std::stoi(next());
      else if (a == "--seeds") seeds = std::stoi(next());
      else if (a == "--detector") use_detector = true;
      else if (a == "--sweep") do_sweep = true;
      else if (a == "--border") g_border = std::stoi(next());
      else throw Error("unknown option '" + a + "'; usage: screening_bench [--reps N] [--seeds S] [--detector] [--sweep]");
    }
    if (reps < 1 || seeds < 1) throw Error("--reps and --seeds must be >= 1");
    RealFrame rf = loadRealFrame(use_detector);
    printCounts(rf);
    if (do_sweep) sweep(rf, seeds);
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
