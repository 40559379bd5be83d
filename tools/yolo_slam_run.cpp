// yolo_slam_run: the offline runner (ORB-SLAM2's rgbd_tum equivalent). Reads a TUM RGB-D
// folder, runs detection (own thread, one frame ahead), screening and SLAM frame by frame and
// writes CameraTrajectory.txt, KeyFrameTrajectory.txt and stats.json.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/json.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/progress.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/eval/ate.h"
#include "yolo_slam/io/atomic_file.h"
#include "yolo_slam/io/text_table.h"
#include "yolo_slam/io/trajectory.h"
#include "yolo_slam/io/tum_sequence.h"
#include "yolo_slam/screening/screener.h"
#include "yolo_slam/slam/system.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <opencv2/core.hpp>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <future>
#include <map>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <thread>

using namespace yolo_slam;

namespace {

volatile std::sig_atomic_t g_stop = 0;
// First Ctrl-C: finish the frame and write the results; the handler then reverts to the default
// so a second Ctrl-C quits at once (signal() is async-signal-safe).
void onSignal(int sig) {
  g_stop = 1;
  std::signal(sig, SIG_DFL);
}

const char* kVocabName = "vocab/yolo_slam_orb_k10_L4.vocab";

const char* kUsage =
    "usage: yolo_slam_run --sequence DIR --out DIR [--config YAML] [--max-frames N] [--realtime]\n"
    "                     [--dynamic-mode off|detect|geometry|detect+geometry] [--model DIR]\n"
    "                     [--single-model]\n"
    "                     [--vocabulary FILE | --no-vocabulary] [--boxes-from-gt | --boxes FILE]\n"
    "                     [--track-boxes on|off] [--propagate-labels on|off]\n"
    "                     [--static-box-veto on|off] [--sequential]\n"
    "Runs YOLO-SLAM on a TUM RGB-D folder (rgb.txt/depth.txt or associations.txt) and writes\n"
    "OUT/CameraTrajectory.txt (every tracked frame, TUM format), OUT/KeyFrameTrajectory.txt and\n"
    "OUT/stats.json (counts, ATE if DIR/groundtruth.txt exists, timings, keypoints in boxes /\n"
    "kept / dropped) and, in modes detect and detect+geometry, OUT/boxes_screened.txt (every box\n"
    "screened, per frame: stamp index label x1 y1 x2 y2 score tracked). On a synthetic sequence\n"
    "(DIR/masks/, from yolo_slam_synth) stats.json also gets screening_metrics: recall of the\n"
    "keypoints on the masks of people (person_recall) and of every moving object\n"
    "(dynamic_recall), and retention of the static keypoints inside the boxes.\n"
    "Ctrl-C (or SIGTERM) stops at the next frame and still writes everything (exit code 130); a\n"
    "second Ctrl-C quits at once without writing.\n"
    "  --sequence DIR     the TUM RGB-D folder (required)\n"
    "  --out DIR          output folder, created if missing (required)\n"
    "  --config YAML      settings (Camera.*, ORBextractor.*, Screening.*, Tracking.*,\n"
    "                     LocalMapping.*, LoopClosing.*, System.*, Detector.*); default\n"
    "                     DIR/camera.yaml if it exists\n"
    "  --max-frames N     only the first N frames\n"
    "  --realtime         pace frames at the sequence's timestamps instead of full speed\n"
    "  --dynamic-mode M   override Screening.mode of the config: off, detect, geometry or\n"
    "                     detect+geometry (the paper's method)\n"
    "  --model DIR        main detector model (folder, .cfg or .onnx); default Detector.model\n"
    "                     (Detector.extraModels still run beside it)\n"
    "  --single-model     run the main model alone (Detector.extraModels: \"\")\n"
    "  --vocabulary FILE  ORB vocabulary (binary or ORBvoc.txt) for BoW matching; default the\n"
    "                     package's vocab/yolo_slam_orb_k10_L4.vocab when it exists\n"
    "  --no-vocabulary    run without BoW: no BoW matching, relocalisation or loop closing\n"
    "  --boxes-from-gt    person boxes from the sequence's boxes.txt (synthetic ground truth)\n"
    "                     instead of running the detector\n"    "  --boxes FILE       replay the detector's boxes of an earlier run (its OUT/boxes_screened.txt,\n"
    "                     with their scores) instead of running the detector\n"
    "  --track-boxes B    override Screening.trackBoxes: on carries person boxes over frames\n"
    "                     where the detector misses them (modes detect, detect+geometry);\n"
    "                     screening metrics count the boxes actually screened\n"
    "  --propagate-labels B  override Screening.propagateLabels: on marks keypoints matching a\n"
    "                     moving dynamic keypoint of the previous frame dynamic (every mode\n"
    "                     but off)\n"
    "  --static-box-veto B  override Screening.staticBoxVeto: on keeps the keypoints of a box\n"
    "                     whose dropped keypoints all sit where static points would be\n"
    "  --sequential       set System.sequential: local mapping and loop closing run after\n"
    "                     each frame in the main thread, so a run repeats bit for bit\n"
    "  -h, --help         this text\n";

struct Args {
  std::string sequence, config, out, model, vocabulary, dynamic_mode, track_boxes,
      propagate_labels, static_box_veto, boxes_file;
  long max_frames = -1;
  bool realtime = false, boxes_from_gt = false, no_vocabulary = false, vocabulary_given = false,
       single_model = false, sequential = false;
};

Args parseArgs(int argc, char** argv) {
  Args a;
  auto need = [&](int& i, const std::string& flag) -> std::string {
    if (i + 1 >= argc) throw Error("missing value after " + flag + "\n" + kUsage);
    return argv[++i];
  };
  for (int i = 1; i < argc; ++i) {
    std::string s = argv[i];
    if (s == "--sequence") a.sequence = need(i, s);
    else if (s == "--config") a.config = need(i, s);
    else if (s == "--out") a.out = need(i, s);
    else if (s == "--model") a.model = need(i, s);
    else if (s == "--single-model") a.single_model = true;
    else if (s == "--vocabulary") a.vocabulary = need(i, s), a.vocabulary_given = true;
    else if (s == "--no-vocabulary") a.no_vocabulary = true;
    else if (s == "--dynamic-mode") a.dynamic_mode = need(i, s);
    else if (s == "--realtime") a.realtime = true;
    else if (s == "--sequential") a.sequential = true;
    else if (s == "--boxes-from-gt") a.boxes_from_gt = true;
    else if (s == "--boxes") a.boxes_file = need(i, s);
    else if (s == "--propagate-labels") {
      a.propagate_labels = need(i, s);
      if (a.propagate_labels != "on" && a.propagate_labels != "off")
        throw Error("--propagate-labels must be on or off (got '" + a.propagate_labels + "')");
    } else if (s == "--static-box-veto") {
      a.static_box_veto = need(i, s);
      if (a.static_box_veto != "on" && a.static_box_veto != "off")
        throw Error("--static-box-veto must be on or off (got '" + a.static_box_veto + "')");
    } else if (s == "--track-boxes") {
      a.track_boxes = need(i, s);
      if (a.track_boxes != "on" && a.track_boxes != "off")
        throw Error("--track-boxes must be on or off (got '" + a.track_boxes + "')");
    }
    else if (s == "--max-frames") {
      std::string v = need(i, s);
      char* end = nullptr;
      a.max_frames = std::strtol(v.c_str(), &end, 10);
      if (!end || *end || a.max_frames <= 0) throw Error("--max-frames must be a positive integer (got '" + v + "')");
    } else if (s == "-h" || s == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else {
      throw Error("unknown option '" + s + "'; see --help");
    }
  }
  if (a.sequence.empty() || a.out.empty())
    throw Error(std::string("--sequence and --out are required\n") + kUsage);
  if (a.vocabulary_given && a.no_vocabulary) throw Error("--vocabulary and --no-vocabulary exclude each other");
  if (a.boxes_from_gt && !a.boxes_file.empty()) throw Error("--boxes and --boxes-from-gt exclude each other");
  if (a.config.empty()) {
    // yolo_slam_synth writes camera.yaml beside the images; real TUM folders need --config.
    a.config = joinPath(a.sequence, "camera.yaml");
    if (!fileExists(a.config))
      throw Error(a.config + ": not found; pass the settings file with --config YAML (e.g. config/TUM3.yaml for TUM freiburg3)");
  }
  if (a.vocabulary_given) {
    if (!fileExists(a.vocabulary))
      throw Error(a.vocabulary + ": vocabulary file not found; fix the path or run without BoW (--no-vocabulary)");
  } else if (!a.no_vocabulary) {
    // Like ORB-SLAM2 loading ORBvoc.txt: BoW is on unless asked otherwise.
    const std::string shipped = joinPath(packageDir(), kVocabName);
    if (fileExists(shipped)) a.vocabulary = shipped;
  }
  return a;
}

// Person boxes per frame from a file, keyed by the stamp in microseconds. Two formats:
// - ground truth: a synthetic sequence's boxes.txt, "rgb_stamp id class x1 y1 x2 y2
//   visible_fraction"; persons only (what the detector is asked for), score 1;
// - replay: a run's boxes_screened.txt, "rgb_stamp index label x1 y1 x2 y2 score tracked";
//   the detector's boxes with their scores (rows with tracked 1 were carried by the box tracker,
//   which carries them again in this run).
std::map<long long, detection::Boxes> readBoxFile(const std::string& path, bool replay) {
  if (!fileExists(path))
    throw Error(path + (replay ? ": not found; --boxes needs a boxes_screened.txt written by yolo_slam_run"
                               : ": not found; --boxes-from-gt needs a synthetic sequence (yolo_slam_synth writes boxes.txt)"));
  std::map<long long, detection::Boxes> out;
  for (const auto& row : io::readTextTable(path)) {
    if (replay && row.fields.size() < 9)
      io::throwAtLine(path, row.line, "expected 'rgb_stamp index label x1 y1 x2 y2 score tracked'");
    if (!replay && row.fields.size() < 7)
      io::throwAtLine(path, row.line, "expected 'stamp id class x1 y1 x2 y2 [visible]'");
    const double stamp = io::parseFiniteDouble(row.fields[0], path, row.line, "stamp");
    if (!replay && row.fields[2] != "person") continue;
    if (replay && row.fields[8] != "0") continue;
    double c[4];
    for (int k = 0; k < 4; ++k) c[k] = io::parseFiniteDouble(row.fields[3 + k], path, row.line, "box corner");
    detection::Box b;
    b.class_id = 0;
    b.label = row.fields[2];
    b.score = replay ? static_cast<float>(io::parseFiniteDouble(row.fields[7], path, row.line, "score")) : 1.f;
    b.rect = cv::Rect2f(static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2] - c[0]),
                        static_cast<float>(c[3] - c[1]));
    out[std::llround(stamp * 1e6)].push_back(b);
  }
  return out;
}

// One frame as prepared by the worker: images, boxes and what went wrong.
struct Prepared {
  size_t index = 0;
  double stamp = 0;
  cv::Mat bgr, depth;
  detection::Boxes boxes;
  bool has_image = false;
  std::string warning;
  double detection_ms = -1;
  cv::Mat mask;  // ground-truth dynamic mask (synthetic sequences), empty if none
  std::string mask_path;
};

std::string baseName(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// num/den as JSON; null without a denominator (e.g. no box in modes off/geometry).
std::string jsonRatio(long num, long den) { return den > 0 ? jsonNumber(static_cast<double>(num) / den, 4) : "null"; }

std::string percent(long num, long den) {
  if (den <= 0) return "n/a (none)";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f%% (%ld of %ld)", 100.0 * num / den, num, den);
  return buf;
}

// Screening quality summed over the frames that have a ground-truth mask.
struct MetricsAccumulator {
  screening::ScreeningMetrics sum;
  size_t frames = 0;

  std::string json() const {
    if (frames == 0) return "null";
    std::ostringstream os;
    os << "{\"frames\": " << frames << ", \"dynamic_keypoints\": " << sum.dynamic_total
       << ", \"dropped\": " << sum.dynamic_dropped
       << ", \"dynamic_recall\": " << jsonRatio(sum.dynamic_dropped, sum.dynamic_total)
       << ", \"dynamic_outside_boxes\": " << sum.dynamic_outside_boxes
       << ", \"dynamic_outside_dropped\": " << sum.dynamic_outside_dropped
       << ", \"dynamic_recall_in_boxes\": "
       << jsonRatio(sum.dynamic_dropped - sum.dynamic_outside_dropped,
                    sum.dynamic_total - sum.dynamic_outside_boxes)
       << ", \"person_keypoints\": " << sum.person_total << ", \"person_dropped\": " << sum.person_dropped
       << ", \"person_recall\": " << jsonRatio(sum.person_dropped, sum.person_total)
       << ", \"static_in_boxes\": " << sum.static_in_boxes << ", \"kept\": " << sum.static_in_boxes_kept
       << ", \"static_retention\": " << jsonRatio(sum.static_in_boxes_kept, sum.static_in_boxes)
       << ", \"static_keypoints\": " << sum.static_total << ", \"static_dropped\": " << sum.static_dropped
       << ", \"static_drop_rate\": " << jsonRatio(sum.static_dropped, sum.static_total) << "}";
    return os.str();
  }
};

void makeDirs(const std::string& dir) {
  std::string cur;
  std::stringstream ss(dir);
  std::string part;
  if (!dir.empty() && dir[0] == '/') cur = "/";
  while (std::getline(ss, part, '/')) {
    if (part.empty()) continue;
    cur += part + "/";
    ::mkdir(cur.c_str(), 0755);
  }
  if (!dirExists(dir)) throw Error(dir + ": cannot create the output folder; check the path and permissions");
}

int run(const Args& args) {
  Config cfg = Config::fromFile(args.config);
  CameraModel cam = CameraModel::load(cfg);
  slam::SystemOptions sys_opt = slam::SystemOptions::load(cfg);
  if (!args.dynamic_mode.empty()) sys_opt.screening.mode = screening::parseDynamicMode(args.dynamic_mode);
  if (!args.track_boxes.empty()) sys_opt.screening.track_boxes = args.track_boxes == "on";
  if (!args.propagate_labels.empty()) sys_opt.screening.propagate_labels = args.propagate_labels == "on";
  if (!args.static_box_veto.empty()) sys_opt.screening.static_box_veto = args.static_box_veto == "on";
  if (args.sequential) sys_opt.sequential = true;
  const screening::DynamicMode mode = sys_opt.screening.mode;
  const bool needs_boxes = mode == screening::DynamicMode::Detect || mode == screening::DynamicMode::DetectGeometry;

  io::TumSequence seq = io::TumSequence::open(args.sequence);
  size_t n = seq.size();
  if (args.max_frames > 0) n = std::min(n, static_cast<size_t>(args.max_frames));

  std::map<long long, detection::Boxes> gt_boxes;
  std::unique_ptr<detection::Detector> detector;
  std::string detector_name = "none";
  if (needs_boxes) {
    if (args.boxes_from_gt) {
      gt_boxes = readBoxFile(joinPath(args.sequence, "boxes.txt"), false);
      detector_name = "ground-truth boxes.txt";
    } else if (!args.boxes_file.empty()) {
      gt_boxes = readBoxFile(args.boxes_file, true);
      detector_name = args.boxes_file;
    } else {
      detection::DetectorOptions dopt = detection::DetectorOptions::load(cfg);
      if (!args.model.empty()) dopt.model = args.model;
      if (args.single_model) dopt.extra_models.clear();
      detector = detection::makeDetector(dopt);
      detector_name = dopt.model;
      for (const auto& m : dopt.extra_models) detector_name += " + " + m;
    }
  }
  std::shared_ptr<const vocabulary::Vocabulary> voc;
  if (!args.vocabulary.empty()) voc = vocabulary::Vocabulary::load(args.vocabulary);
  makeDirs(args.out);
  // Synthetic sequences carry per-frame masks (masks/<rgb file name>): screening metrics.
  const std::string mask_dir = joinPath(args.sequence, "masks");
  const bool has_masks = dirExists(mask_dir);

  slam::System system(cam, sys_opt, voc);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  // Printed once the handlers are in place (the Ctrl-C test waits for this line).
  std::fprintf(stderr, "yolo_slam_run: %zu frames from %s, dynamic mode %s, boxes: %s, vocabulary: %s%s\n", n,
               args.sequence.c_str(), screening::toString(mode).c_str(), detector_name.c_str(),
               args.vocabulary.empty() ? "none (no BoW)" : args.vocabulary.c_str(),
               has_masks ? ", screening metrics from masks/" : "");

  // Worker: loads frame i and detects people in it (the detector is used by one task at a time).
  auto prepare = [&](size_t i) {
    Prepared p;
    p.index = i;
    p.stamp = seq.frames()[i].rgb_stamp;
    try {
      p.bgr = seq.loadRgb(i);
      p.has_image = !p.bgr.empty();
    } catch (const std::exception& e) {
      p.warning = e.what();
      return p;
    }
    try {
      p.depth = seq.loadDepth(i, cam.depth_map_factor);
    } catch (const std::exception& e) {
      p.warning = std::string(e.what()) + " (tracked without depth)";
      p.depth = cv::Mat();
    }
    if (needs_boxes) {
      if (detector) {
        Stopwatch sw;
        try {
          p.boxes = detector->detect(p.bgr);
        } catch (const std::exception& e) {
          p.warning = std::string("detector failed: ") + e.what();
        }
        p.detection_ms = sw.ms();
      } else {
        auto it = gt_boxes.find(std::llround(p.stamp * 1e6));
        if (it != gt_boxes.end()) p.boxes = it->second;
      }
    }
    if (has_masks) {
      // A frame without a mask is simply not evaluated; an unreadable one is reported.
      p.mask_path = joinPath(mask_dir, baseName(seq.frames()[i].rgb_path));
      if (fileExists(p.mask_path)) {
        try {
          p.mask = screening::loadMask(p.mask_path);
        } catch (const std::exception& e) {
          p.warning += (p.warning.empty() ? "" : "; ") + std::string(e.what()) + " (frame not evaluated)";
        }
      }
    }
    return p;
  };

  ProgressBar bar("yolo_slam_run", n);
  std::vector<double> frame_ms;
  size_t skipped = 0, processed = 0, lost_reports = 0;
  MetricsAccumulator metrics;
  Stopwatch total;
  const auto wall0 = std::chrono::steady_clock::now();
  const double stamp0 = n ? seq.frames()[0].rgb_stamp : 0;
  // Every box screened, per frame, in the synthetic boxes.txt format: to inspect the detector
  // and the box tracker offline, or to score them against the ground truth.
  std::ofstream boxes_out;
  if (needs_boxes) {
    boxes_out.open(joinPath(args.out, "boxes_screened.txt"));
    boxes_out << "# rgb_stamp index label x1 y1 x2 y2 score tracked\n";
  }
  std::future<Prepared> next;
  if (n > 0) next = std::async(std::launch::async, prepare, size_t{0});
  for (size_t i = 0; i < n && !g_stop; ++i) {
    Stopwatch fsw;
    Prepared p = next.get();
    // Detection of frame i+1 overlaps the tracking of frame i.
    if (i + 1 < n) next = std::async(std::launch::async, prepare, i + 1);
    if (args.realtime) {
      const auto due = wall0 + std::chrono::duration<double>(p.stamp - stamp0);
      std::this_thread::sleep_until(std::chrono::time_point_cast<std::chrono::steady_clock::duration>(due));
    }
    if (!p.warning.empty()) std::fprintf(stderr, "\nwarning: frame %zu (%.6f): %s\n", i, p.stamp, p.warning.c_str());
    if (p.detection_ms >= 0) system.recordDetectionTime(p.detection_ms);
    if (!p.has_image) {
      ++skipped;
    } else {
      slam::TrackResult r = system.trackRgbd(p.bgr, p.depth, p.stamp, p.boxes);
      if (r.state != slam::TrackingState::Ok) ++lost_reports;
      ++processed;
      if (boxes_out.is_open()) {
        int k = 0;
        char line[160];
        for (const auto& b : system.lastBoxes()) {
          std::snprintf(line, sizeof line, "%.6f %d %s %.1f %.1f %.1f %.1f %.3f %d\n", p.stamp, k++,
                        b.label.empty() ? "person" : b.label.c_str(), b.rect.x, b.rect.y,
                        b.rect.x + b.rect.width, b.rect.y + b.rect.height, b.score, b.tracked ? 1 : 0);
          boxes_out << line;
        }
      }
      if (!p.mask.empty()) {
        // Retention counts static keypoints inside the boxes this run used (none in modes
        // off/geometry); exact synthetic masks need no ignored border.
        try {
          metrics.sum += screening::evaluateScreening(system.lastFrame(), p.mask, system.lastBoxes(), 0);
          ++metrics.frames;
        } catch (const Error& e) {
          std::fprintf(stderr, "\nwarning: %s: %s (frame not evaluated)\n", p.mask_path.c_str(), e.what());
        }
      }
    }
    frame_ms.push_back(fsw.ms());
    char extra[96];
    std::snprintf(extra, sizeof extra, "%s, lost %zu", slam::toString(system.state()), lost_reports);
    bar.update(i + 1, extra);
  }
  if (next.valid()) next.wait();
  bar.finish();
  const double total_s = total.ms() / 1000.0;
  if (g_stop) std::fprintf(stderr, "interrupted: stopping after %zu frames and writing the results\n", processed + skipped);

  system.waitForLocalMapping();
  system.shutdown();
  Trajectory traj = system.cameraTrajectory();
  Trajectory kfs = system.keyframeTrajectory();
  io::writeTrajectory(joinPath(args.out, "CameraTrajectory.txt"), traj);
  io::writeTrajectory(joinPath(args.out, "KeyFrameTrajectory.txt"), kfs);

  double ate_rmse = NAN;
  size_t ate_pairs = 0;
  if (seq.hasGroundTruth() && traj.size() >= 2) {
    try {
      eval::AteResult ate = eval::computeAte(seq.groundTruth(), traj);
      ate_rmse = ate.stats.rmse;
      ate_pairs = ate.stats.count;
    } catch (const Error& e) {
      std::fprintf(stderr, "warning: ATE not computed: %s\n", e.what());
    }
  }

  slam::SystemStats s = system.stats();
  std::ostringstream js;
  js << "{\n  \"sequence\": \"" << jsonEscape(args.sequence) << "\",\n  \"config\": \"" << jsonEscape(args.config)
     << "\",\n  \"dynamic_mode\": \"" << screening::toString(mode) << "\",\n  \"boxes\": \""
     << jsonEscape(detector_name) << "\",\n  \"interrupted\": " << (g_stop ? "true" : "false")
     << ",\n  \"frames_skipped\": " << skipped << ",\n  \"trajectory_poses\": " << traj.size()
     << ",\n  \"ate_rmse_m\": " << jsonNumber(ate_rmse, 6)
     << ",\n  \"ate_pairs\": " << ate_pairs << ",\n  \"wall_time_s\": " << jsonNumber(total_s, 3)
     << ",\n  \"fps\": " << jsonNumber(total_s > 0 ? (processed + skipped) / total_s : 0, 4) << ",\n"
     << slam::statsCountsJson(s)
     << ",\n  \"track_boxes\": " << (sys_opt.screening.track_boxes && needs_boxes ? "true" : "false")
     << ",\n  \"propagate_labels\": "
     << (sys_opt.screening.propagate_labels && mode != screening::DynamicMode::Off ? "true" : "false")
     << ",\n  \"static_box_veto\": "
     << (sys_opt.screening.static_box_veto && mode != screening::DynamicMode::Off ? "true" : "false")
     << ",\n  \"sequential\": " << (sys_opt.sequential ? "true" : "false")
     << ",\n  \"vocabulary\": \"" << jsonEscape(args.vocabulary) << "\""
     << ",\n  \"screening_metrics\": " << metrics.json() << ",\n"
     << slam::statsTimingsJson(s, {{"frame", frame_ms}}) << "\n}\n";
  const std::string stats_path = joinPath(args.out, "stats.json");
  io::writeFileAtomic(stats_path, js.str());

  std::printf("frames %zu, tracked %zu, lost %zu, keyframes %zu, map points %zu\n", s.frames, s.tracked, s.lost,
              s.keyframes, s.map_points);
  const auto t = summarize(slam::extractionPlusTrackingMs(s));
  std::printf("extraction+tracking median %.2f ms, p95 %.2f ms; %.1f frames/s overall\n", t.median, t.p95,
              total_s > 0 ? (processed + skipped) / total_s : 0.0);
  if (std::isfinite(ate_rmse)) std::printf("ATE RMSE %.4f m over %zu poses\n", ate_rmse, ate_pairs);
  if (metrics.frames > 0)
    std::printf("screening vs masks over %zu frames: dynamic recall %s (on people %s), static retention "
                "in boxes %s, static dropped %s\n",
                metrics.frames, percent(metrics.sum.dynamic_dropped, metrics.sum.dynamic_total).c_str(),
                percent(metrics.sum.person_dropped, metrics.sum.person_total).c_str(),
                percent(metrics.sum.static_in_boxes_kept, metrics.sum.static_in_boxes).c_str(),
                percent(metrics.sum.static_dropped, metrics.sum.static_total).c_str());
  if (sys_opt.screening.track_boxes && needs_boxes)
    std::printf("boxes screened: %ld from the detector, %ld carried by the box tracker\n", s.boxes_detected,
                s.boxes_tracked);
  if (sys_opt.screening.propagate_labels && mode != screening::DynamicMode::Off)
    std::printf("label propagation marked %ld keypoints dynamic\n", s.keypoints_propagated);
  if (sys_opt.screening.static_box_veto && mode != screening::DynamicMode::Off)
    std::printf("static-box veto: %ld boxes left alone, %ld screened keypoints kept\n",
                s.boxes_vetoed, s.keypoints_vetoed);
  if (metrics.frames > 0)
    std::printf("dynamic keypoints outside every box: %s dropped\n",
                percent(metrics.sum.dynamic_outside_dropped, metrics.sum.dynamic_outside_boxes).c_str());
  std::printf("wrote %s/{CameraTrajectory.txt,KeyFrameTrajectory.txt,stats.json}\n", args.out.c_str());
  return g_stop ? 130 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parseArgs(argc, argv));
  } catch (const Error& e) {
    std::string msg = e.what();
    // One line: usage text after the first line is printed separately.
    auto nl = msg.find('\n');
    std::fprintf(stderr, "error: %s\n", msg.substr(0, nl).c_str());
    if (nl != std::string::npos) std::fputs(msg.substr(nl + 1).c_str(), stderr);
    return 1;
  } catch (const cv::Exception& e) {
    std::fprintf(stderr, "error: OpenCV: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
