// yolo_slam_run: the offline runner (ORB-SLAM2's rgbd_tum equivalent). Reads a TUM RGB-D
// folder, runs detection (own thread, one frame ahead), screening and SLAM frame by frame and
// writes CameraTrajectory.txt, KeyFrameTrajectory.txt and stats.json; optionally starts in a map
// loaded from a file and saves the map at the end (slam/map_file.h). Every output is checked
// before the first frame, the tracking poses are appended to CameraTrajectory.partial.txt as
// they are estimated, and stats.json, written last, says whether the run is complete.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/json.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/progress.h"
#include "yolo_slam/common/thread_name.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/detection/async_detector.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/eval/ate.h"
#include "yolo_slam/io/atomic_file.h"
#include "yolo_slam/io/camera_feed.h"
#include "yolo_slam/io/playback.h"
#include "yolo_slam/io/run_output.h"
#include "yolo_slam/io/text_table.h"
#include "yolo_slam/io/trajectory.h"
#include "yolo_slam/io/tum_sequence.h"
#include "yolo_slam/screening/screener.h"
#include "yolo_slam/slam/system.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <opencv2/core.hpp>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <future>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

using namespace yolo_slam;

namespace {

// Written by the signal handler only, read by the frame loop and the waits. Lock-free atomics:
// the handler may run in any thread, several at once when signals arrive together.
std::atomic<int> g_stop{0};     // number of the first stop signal; 0 while none came
std::atomic<int> g_signals{0};  // stop signals received
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

// The signal that quits at once without the results. The first stops the run and has the
// results written; the second is only acknowledged, since an impatient second Ctrl-C 50 ms
// later, while they are being written, must not lose the whole run.
constexpr int kForceQuitSignal = 3;
constexpr int kExitError = 1;
constexpr int kExitTooFewTracked = 3;
constexpr int kExitSignalBase = 128;  // 128 + signal number, as a shell reports it
constexpr double kDefaultMinTracked = 0.1;

// The handler, async-signal-safe: lock-free atomics, write(2) and _exit only.
void onStopSignal(int sig) {
  const int n = g_signals.fetch_add(1) + 1;
  if (n == 1) {
    g_stop = sig;
    return;
  }
  if (n < kForceQuitSignal) {
    static const char msg[] = "\nyolo_slam_run: stopping and writing the results; one more signal quits without them\n";
    (void)!::write(STDERR_FILENO, msg, sizeof msg - 1);
    return;
  }
  static const char msg[] = "\nyolo_slam_run: quitting at once; the poses so far are in CameraTrajectory.partial.txt\n";
  (void)!::write(STDERR_FILENO, msg, sizeof msg - 1);
  ::_exit(kExitSignalBase + sig);
}

constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

// SIGINT, SIGTERM and SIGHUP (an ssh session dropped) stop the run and write the results;
// SIGPIPE is ignored, so output to a closed pipe (| head) fails quietly and the run goes on.
void installSignalHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onStopSignal;
  sigemptyset(&sa.sa_mask);
  for (int sig : kStopSignals) sigaddset(&sa.sa_mask, sig);
  sa.sa_flags = SA_RESTART;
  for (int sig : kStopSignals) ::sigaction(sig, &sa, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
}

bool stopRequested() { return g_stop != 0; }

const char* kVocabName = "vocab/yolo_slam_orb_k10_L4.vocab";

const char* kUsage =
    "usage: yolo_slam_run --sequence DIR --out DIR [--config YAML] [--max-frames N]\n"
    "                     [--min-tracked F] [--realtime | --camera-rate] [--preload]\n"
    "                     [--detection async|every-frame]\n"
    "                     [--dynamic-mode off|detect|geometry|detect+geometry] [--model DIR]\n"
    "                     [--single-model]\n"
    "                     [--vocabulary FILE | --no-vocabulary] [--boxes-from-gt | --boxes FILE]\n"
    "                     [--track-boxes on|off] [--propagate-labels on|off]\n"
    "                     [--static-box-veto on|off] [--sequential] [--set KEY=VALUE ...]\n"
    "                     [--load-map FILE] [--save-map FILE] [--localization]\n"
    "                     [--octomap OUT.bt] [--cloud OUT.ply]\n"
    "Runs YOLO-SLAM on a TUM RGB-D folder (rgb.txt/depth.txt or associations.txt) and writes\n"
    "OUT/CameraTrajectory.txt (every tracked frame, TUM format), OUT/KeyFrameTrajectory.txt and\n"
    "OUT/stats.json (counts, ATE if DIR/groundtruth.txt exists, timings, keypoints in boxes /\n"
    "kept / dropped) and, in modes detect and detect+geometry, OUT/boxes_screened.txt (every box\n"
    "screened, per frame: stamp index label x1 y1 x2 y2 score tracked). OUT/frames.txt has a\n"
    "line per frame: state, inliers, keypoints, dynamic ones, boxes, how many frames older the\n"
    "image of its new detection is (0: its own; -1: none new), keyframe, the screening counts\n"
    "against its mask, latency. On a synthetic sequence\n"
    "(DIR/masks/, from yolo_slam_synth) stats.json also gets screening_metrics: recall of the\n"
    "keypoints on the masks of people (person_recall) and of every moving object\n"
    "(dynamic_recall), and retention of the static keypoints inside the boxes.\n"
    "While it runs, OUT/CameraTrajectory.partial.txt gets every tracking pose as it is estimated\n"
    "(kept after a kill or crash) and stats.json says \"complete\": false until the end.\n"
    "Ctrl-C, SIGTERM or SIGHUP stops at the next frame and still writes everything (exit code\n"
    "128 + signal: 130 for Ctrl-C); a second one is ignored, a third quits at once without them\n"
    "(the partial trajectory stays). Exit code 3: fewer frames tracked than --min-tracked\n"
    "(everything is still written); 1: bad arguments, unreadable input, unwritable output.\n"
    "  --sequence DIR     the TUM RGB-D folder (required)\n"
    "  --out DIR          output folder, created if missing (required)\n"
    "  --config YAML      settings (Camera.*, ORBextractor.*, Screening.*, Tracking.*,\n"
    "                     LocalMapping.*, LoopClosing.*, System.*, Detector.*); default\n"
    "                     DIR/camera.yaml if it exists\n"
    "  --max-frames N     only the first N frames\n"
    "  --min-tracked F    exit code 3 when fewer than this fraction of the frames got a pose\n"
    "                     (default 0.1; 0 accepts any run)\n"
    "  --realtime         pace frames at the sequence's timestamps instead of full speed (a\n"
    "                     forward stamp gap over 2 s is played as 2 s, with a warning)\n"
    "  --camera-rate      feed frames at the sequence's timestamps as a camera does: a frame\n"
    "                     that arrives while the pipeline is busy replaces the waiting one\n"
    "                     (dropped); stats.json \"camera\" has offered/processed/dropped frames\n"
    "                     and the latency from a frame's arrival to its pose\n"
    "  --preload          read every frame before the clock starts, as --camera-rate does: the\n"
    "                     frame rate then measures the pipeline fed decoded images, as a\n"
    "                     camera feeds it, without the PNG decoding of the folder (about 2.5 MB\n"
    "                     of memory per 640x480 frame)\n"
    "  --detection M      --set Detection.async=1 (async: the detector works on the newest\n"
    "                     frame whenever it is free, frames never wait for it) or 0\n"
    "                     (every-frame, the default of config/TUM*.yaml: each frame is\n"
    "                     detected before it is screened, the paper's pipeline)\n"
    "  --set KEY=VALUE    override a settings key (repeatable; YAML value: a number, a word or\n"
    "                     [a, b]), e.g. --set Screening.boxDilation=0.1; the effective settings\n"
    "                     are written to stats.json (\"settings\")\n"
    "  --dynamic-mode M   --set Screening.mode=M: off, detect, geometry or detect+geometry\n"
    "                     (the paper's method)\n"
    "  --model DIR        main detector model (folder, .cfg or .onnx); default Detector.model\n"
    "                     (Detector.extraModels still run beside it)\n"
    "  --single-model     run the main model alone (Detector.extraModels: \"\")\n"
    "  --vocabulary FILE  ORB vocabulary (binary or ORBvoc.txt) for BoW matching; default the\n"
    "                     package's vocab/yolo_slam_orb_k10_L4.vocab when it exists\n"
    "  --no-vocabulary    run without BoW: no BoW matching, relocalisation or loop closing\n"
    "  --boxes-from-gt    person boxes from the sequence's boxes.txt (synthetic ground truth)\n"
    "                     instead of running the detector\n"
    "  --boxes FILE       replay the detector's boxes of an earlier run (its OUT/boxes_screened.txt,\n"
    "                     with their scores) instead of running the detector\n"
    "  --track-boxes B    --set Screening.trackBoxes (on/off): on carries person boxes over frames\n"
    "                     where the detector misses them (modes detect, detect+geometry);\n"
    "                     screening metrics count the boxes actually screened\n"
    "  --propagate-labels B  --set Screening.propagateLabels (on/off): on marks keypoints matching a\n"
    "                     moving dynamic keypoint of the previous frame dynamic (every mode\n"
    "                     but off)\n"
    "  --static-box-veto B  --set Screening.staticBoxVeto (on/off): on keeps the keypoints of a box\n"
    "                     whose dropped keypoints all sit where static points would be\n"
    "  --sequential       --set System.sequential=1: local mapping and loop closing run after\n"
    "                     each frame in the main thread, so a run repeats bit for bit\n"
    "  --load-map FILE    start in the map saved in FILE (by --save-map, with the same camera,\n"
    "                     ORB pyramid and vocabulary): tracking starts lost and relocalises, so\n"
    "                     the trajectory is in the loaded map's frame\n"
    "  --save-map FILE    write the map to FILE at the end (also after Ctrl-C); stats.json\n"
    "                     \"map_file\" has its size and the save and load times\n"
    "  --localization     track against the map without adding keyframes or points (with\n"
    "                     --load-map: localisation in a prebuilt map)\n"
    "  --octomap FILE     --set DenseMap.enabled=1 and write the dense static map (people left\n"
    "                     out) as an OctoMap .bt file at the end; stats.json \"dense_map\"\n"
    "  --cloud FILE       the same, and its coloured point cloud as binary PLY\n"
    "  -h, --help         this text\n";

struct Args {
  std::string sequence, config, out, model, vocabulary, boxes_file, load_map, save_map;
  std::string octomap, cloud;  // dense map outputs (--octomap, --cloud)
  // Settings overrides in command-line order (--set and the flags that stand for a key).
  std::vector<std::string> overrides;
  long max_frames = -1;
  double min_tracked = kDefaultMinTracked;
  bool realtime = false, camera_rate = false, preload = false, boxes_from_gt = false, no_vocabulary = false, vocabulary_given = false,
       single_model = false, localization = false;
};

// "on"/"off" of a flag standing for a boolean key, as the key's override.
std::string onOffOverride(const std::string& flag, const std::string& key, const std::string& v) {
  if (v != "on" && v != "off") throw Error(flag + " must be on or off (got '" + v + "')");
  return key + "=" + (v == "on" ? "1" : "0");
}

std::string detectionOverride(const std::string& v) {
  if (v != "async" && v != "every-frame")
    throw Error("--detection must be async or every-frame (got '" + v + "')");
  return std::string("Detection.async=") + (v == "async" ? "1" : "0");
}

long positiveLong(const std::string& flag, const std::string& v) {
  char* end = nullptr;
  const long n = std::strtol(v.c_str(), &end, 10);
  if (!end || *end || n <= 0) throw Error(flag + " must be a positive integer (got '" + v + "')");
  return n;
}

double fractionArg(const std::string& flag, const std::string& v) {
  char* end = nullptr;
  const double f = std::strtod(v.c_str(), &end);
  if (!end || *end || v.empty() || !(f >= 0 && f <= 1))
    throw Error(flag + " must be a fraction in [0, 1] (got '" + v + "')");
  return f;
}

// Fills in the settings file and the vocabulary the user did not name.
void resolveDefaultFiles(Args& a) {
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
}

Args parseArgs(int argc, char** argv) {
  Args a;
  auto need = [&](int& i, const std::string& flag) -> std::string {
    if (i + 1 >= argc) throw Error("missing value after " + flag + "\n" + kUsage);
    return argv[++i];
  };
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    if (s == "--sequence") a.sequence = need(i, s);
    else if (s == "--config") a.config = need(i, s);
    else if (s == "--out") a.out = need(i, s);
    else if (s == "--model") a.model = need(i, s);
    else if (s == "--single-model") a.single_model = true;
    else if (s == "--vocabulary") a.vocabulary = need(i, s), a.vocabulary_given = true;
    else if (s == "--no-vocabulary") a.no_vocabulary = true;
    else if (s == "--set") a.overrides.push_back(need(i, s));
    else if (s == "--dynamic-mode") a.overrides.push_back("Screening.mode=" + need(i, s));
    else if (s == "--realtime") a.realtime = true;
    else if (s == "--camera-rate") a.camera_rate = true;
    else if (s == "--preload") a.preload = true;
    else if (s == "--detection") a.overrides.push_back(detectionOverride(need(i, s)));
    else if (s == "--sequential") a.overrides.push_back("System.sequential=1");
    else if (s == "--boxes-from-gt") a.boxes_from_gt = true;
    else if (s == "--boxes") a.boxes_file = need(i, s);
    else if (s == "--propagate-labels") a.overrides.push_back(onOffOverride(s, "Screening.propagateLabels", need(i, s)));
    else if (s == "--static-box-veto") a.overrides.push_back(onOffOverride(s, "Screening.staticBoxVeto", need(i, s)));
    else if (s == "--track-boxes") a.overrides.push_back(onOffOverride(s, "Screening.trackBoxes", need(i, s)));
    else if (s == "--max-frames") a.max_frames = positiveLong(s, need(i, s));
    else if (s == "--min-tracked") a.min_tracked = fractionArg(s, need(i, s));
    else if (s == "--load-map") a.load_map = need(i, s);
    else if (s == "--save-map") a.save_map = need(i, s);
    else if (s == "--localization") a.localization = true;
    else if (s == "--octomap") a.octomap = need(i, s);
    else if (s == "--cloud") a.cloud = need(i, s);
    else if (s == "-h" || s == "--help") {
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
  if (a.realtime && a.camera_rate) throw Error("--realtime and --camera-rate exclude each other");
  // Outputs written at the end are checked now, not after the whole sequence.
  if (!a.save_map.empty()) io::checkOutputFile(a.save_map, "--save-map");
  if (!a.octomap.empty()) io::checkOutputFile(a.octomap, "--octomap");
  if (!a.cloud.empty()) io::checkOutputFile(a.cloud, "--cloud");
  if (!a.octomap.empty() || !a.cloud.empty()) a.overrides.push_back("DenseMap.enabled=1");
  resolveDefaultFiles(a);
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
  std::chrono::steady_clock::time_point arrival;  // --camera-rate: when the camera gave it
  bool detector_ran = true;  // false: async detection had no new result for this frame
  long detected_image = -1;  // index of the image whose new detection this frame screened (-1: none)
  std::optional<slam::ExtractedFrame> extracted;  // extracted ahead (the extraction stage, not --sequential)
};

std::string baseName(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

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

  Json json() const {
    if (frames == 0) return nullptr;
    Json j{{"frames", frames}};
    j.update(Json(sum));
    return j;
  }
};

// Everything a run reads before its first frame: settings (with the overrides applied before
// anything loads), camera, sequence, where the boxes come from, vocabulary.
struct RunSetup {
  Config cfg;
  CameraModel cam;
  slam::SystemOptions options;
  screening::Stages stages;
  io::TumSequence seq;
  size_t frames = 0;
  std::map<long long, detection::Boxes> file_boxes;  // --boxes-from-gt / --boxes
  std::unique_ptr<detection::Detector> detector;       // every-frame detection
  std::unique_ptr<detection::AsyncDetector> async;     // Detection.async (then detector is null)
  double max_box_age_s = 0;                            // Detection.maxAge
  int max_lag_frames = 0;  // Detection.asyncMaxLag, full-speed runs only (0 at camera pace)
  std::string boxes_source = "none";
  std::shared_ptr<const vocabulary::Vocabulary> voc;
  std::string mask_dir;  // synthetic sequences: per-frame masks, masks/<rgb file name>
  bool has_masks = false;
};

void setUpBoxes(const Args& args, RunSetup& r) {
  if (!r.stages.detection) return;
  if (args.boxes_from_gt) {
    r.file_boxes = readBoxFile(joinPath(args.sequence, "boxes.txt"), false);
    r.boxes_source = "ground-truth boxes.txt";
  } else if (!args.boxes_file.empty()) {
    r.file_boxes = readBoxFile(args.boxes_file, true);
    r.boxes_source = args.boxes_file;
  } else {
    detection::DetectorOptions dopt = detection::DetectorOptions::load(r.cfg);
    if (!args.model.empty()) dopt.model = args.model;
    if (args.single_model) dopt.extra_models.clear();
    const detection::AsyncDetectionOptions aopt = detection::AsyncDetectionOptions::load(r.cfg);
    if (aopt.enabled) dopt.threads = aopt.threads;
    r.detector = detection::makeDetector(dopt);
    r.boxes_source = dopt.model;
    for (const auto& m : dopt.extra_models) r.boxes_source += " + " + m;
    if (aopt.enabled) {
      r.async = std::make_unique<detection::AsyncDetector>(std::move(r.detector), aopt.min_interval_s,
                                                          aopt.thread_nice);
      r.max_box_age_s = aopt.max_age_s;
      if (!args.realtime && !args.camera_rate) r.max_lag_frames = aopt.max_lag_frames;
      r.boxes_source += " (async)";
    }
  }
}

RunSetup setUp(const Args& args) {
  RunSetup r;
  io::prepareOutputFolder(args.out, io::RunFiles::all(), "--out");
  r.cfg = Config::fromFile(args.config);
  for (const auto& o : args.overrides) r.cfg.setFromAssignment(o);
  r.cam = CameraModel::load(r.cfg);
  r.options = slam::SystemOptions::load(r.cfg);
  r.stages = screening::stagesFor(r.options.screening);
  r.seq = io::TumSequence::open(args.sequence);
  r.frames = r.seq.size();
  if (args.max_frames > 0) r.frames = std::min(r.frames, static_cast<size_t>(args.max_frames));
  setUpBoxes(args, r);
  if (!args.vocabulary.empty()) r.voc = vocabulary::Vocabulary::load(args.vocabulary);
  r.mask_dir = joinPath(args.sequence, "masks");
  r.has_masks = dirExists(r.mask_dir);
  return r;
}

void detectInto(const RunSetup& r, Prepared& p) {
  if (!r.stages.detection || !p.has_image) return;
  if (r.async) {
    r.async->offer(p.bgr, static_cast<long>(p.index), p.stamp);
    return;
  }
  p.detected_image = static_cast<long>(p.index);
  if (!r.detector) {
    auto it = r.file_boxes.find(std::llround(p.stamp * 1e6));
    if (it != r.file_boxes.end()) p.boxes = it->second;
    return;
  }
  Stopwatch sw;
  try {
    p.boxes = r.detector->detect(p.bgr);
  } catch (const std::exception& e) {
    p.warning = std::string("detector failed: ") + e.what();
  }
  p.detection_ms = sw.ms();
}

void loadMaskInto(const RunSetup& r, size_t i, Prepared& p) {
  if (!r.has_masks) return;
  // A frame without a mask is simply not evaluated; an unreadable one is reported.
  p.mask_path = joinPath(r.mask_dir, baseName(r.seq.frames()[i].rgb_path));
  if (!fileExists(p.mask_path)) return;
  try {
    p.mask = screening::loadMask(p.mask_path);
  } catch (const std::exception& e) {
    p.warning += (p.warning.empty() ? "" : "; ") + std::string(e.what()) + " (frame not evaluated)";
  }
}

// Reads frame i: image, depth and (synthetic sequences) the ground-truth mask.
Prepared loadFrame(const RunSetup& r, size_t i) {
  Prepared p;
  p.index = i;
  p.stamp = r.seq.frames()[i].rgb_stamp;
  try {
    p.bgr = r.seq.loadRgb(i);
    p.has_image = !p.bgr.empty();
  } catch (const std::exception& e) {
    p.warning = e.what();
    return p;
  }
  try {
    p.depth = r.seq.loadDepth(i, r.cam.depth_map_factor);
  } catch (const std::exception& e) {
    p.warning = std::string(e.what()) + " (tracked without depth)";
    p.depth = cv::Mat();
  }
  loadMaskInto(r, i, p);
  return p;
}

// Why frames got no pose, for the summary of a run that tracked too little.
struct UntrackedCounts {
  size_t no_image = 0;      // image missing or unreadable: the frame was skipped
  size_t no_depth = 0;      // no depth image, none of its pixels valid, or not the image's size
  size_t no_keypoints = 0;  // no keypoint found (black, blank or saturated image)
  size_t lost = 0;          // tracked but lost (or not yet initialised)

  Json json() const {
    return Json{{"no_image", no_image}, {"no_depth", no_depth}, {"no_keypoints", no_keypoints}, {"lost", lost}};
  }
};

// What the frame loop counted.
struct LoopResult {
  size_t skipped = 0, processed = 0, lost_reports = 0;
  UntrackedCounts untracked;
  std::vector<double> frame_ms;
  std::vector<double> latency_ms;  // --camera-rate: arrival to pose
  long camera_offered = 0, camera_dropped = 0;
  long boxes_fresh = 0, boxes_expired = 0;  // async detection: frames given a new result
  MetricsAccumulator metrics;
  double total_s = 0;
  double fps() const { return total_s > 0 ? static_cast<double>(processed + skipped) / total_s : 0.0; }
};

// The stamps of the run's first `count` frames (all of them by default).
std::vector<double> stampsOf(const RunSetup& setup, size_t count = SIZE_MAX) {
  std::vector<double> stamps;
  for (size_t i = 0; i < std::min(count, setup.frames); ++i) stamps.push_back(setup.seq.frames()[i].rgb_stamp);
  return stamps;
}

// Frames in sequence order, each loaded in a worker while the one before it goes through the
// pipeline; --realtime paces them at their stamps (gaps capped, the wait ends on a stop signal).
class PrefetchSource {
 public:
  // `preloaded`: every frame already read (--preload); the worker then only hands them over.
  PrefetchSource(const RunSetup& setup, bool realtime, std::vector<Prepared> preloaded = {})
      : setup_(setup), realtime_(realtime), preloaded_(std::move(preloaded)),
        wall0_(std::chrono::steady_clock::now()), offsets_(io::playbackSchedule(stampsOf(setup)).offsets) {
    if (setup_.frames > 0) start(0);
  }
  ~PrefetchSource() {
    if (next_.valid()) next_.wait();
  }
  std::optional<Prepared> next() {
    if (i_ >= setup_.frames) return std::nullopt;
    Prepared p = next_.get();
    if (++i_ < setup_.frames) start(i_);
    if (realtime_) {
      const auto due = wall0_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                    std::chrono::duration<double>(offsets_[p.index]));
      if (!io::sleepUntilUnlessStopped(due, stopRequested)) return std::nullopt;
    }
    p.arrival = std::chrono::steady_clock::now();
    return p;
  }

 private:
  void start(size_t i) {
    next_ = std::async(std::launch::async, [this, i] {
      nameThisThread("ys_load_frame");
      if (i >= preloaded_.size()) return loadFrame(setup_, i);
      return std::move(preloaded_[i]);
    });
  }
  const RunSetup& setup_;
  const bool realtime_;
  std::vector<Prepared> preloaded_;  // --preload: each moved out once, by the worker
  const std::chrono::steady_clock::time_point wall0_;
  const std::vector<double> offsets_;  // io::playbackSchedule of the stamps
  size_t i_ = 0;
  std::future<Prepared> next_;
};

// Every frame read before the camera starts: a live camera hands over decoded images, so
// decoding the files must not compete with the pipeline (about 2.5 MB per 640x480 frame).
std::vector<Prepared> loadAllFrames(const RunSetup& setup, const char* why) {
  std::fprintf(stderr, "%s: reading %zu frames before the clock starts\n", why, setup.frames);
  std::vector<Prepared> frames;
  frames.reserve(setup.frames);
  for (size_t i = 0; i < setup.frames && !stopRequested(); ++i) frames.push_back(loadFrame(setup, i));
  return frames;
}

// --camera-rate: frames as a live camera gives them (io::CameraFeed), newest wins: a frame that
// arrives while the pipeline's first stage (detection) is busy replaces the waiting one.
class CameraSource {
 public:
  explicit CameraSource(const RunSetup& setup)
      : frames_(loadAllFrames(setup, "--camera-rate")),
        feed_(stampsOf(setup, frames_.size()), [this](size_t i) { return std::move(frames_[i]); }) {}
  std::optional<Prepared> next() {
    std::optional<io::CameraFeed<Prepared>::Arrived> a = feed_.next(stopRequested);
    if (!a) return std::nullopt;
    a->frame.arrival = a->due;
    return std::move(a->frame);
  }
  long offered() const { return feed_.offered(); }
  long dropped() const { return feed_.dropped(); }

 private:
  std::vector<Prepared> frames_;  // each moved out once, by the camera thread
  io::CameraFeed<Prepared> feed_;
};

// A pacing run would otherwise sit silently through a paused recording or a clock jump.
void warnAboutStampGaps(const RunSetup& setup, const char* flag) {
  const std::vector<double> stamps = stampsOf(setup);
  const io::PlaybackSchedule s = io::playbackSchedule(stamps);
  if (s.gaps_capped == 0) return;
  const size_t i = s.first_capped;
  std::fprintf(stderr,
               "warning: stamps jump forward %.3f s from %.6f to %.6f (frame %zu)%s; %s plays a gap over %.0f s "
               "as %.0f s\n",
               stamps[i] - stamps[i - 1], stamps[i - 1], stamps[i], i,
               s.gaps_capped > 1 ? (", and " + std::to_string(s.gaps_capped - 1) + " more such gaps").c_str() : "",
               flag, io::kMaxPlaybackGapS, io::kMaxPlaybackGapS);
}

// Every box screened, per frame, in the synthetic boxes.txt format: to inspect the detector
// and the box tracker offline, or to score them against the ground truth.
std::string screenedBoxLines(double stamp, const detection::Boxes& boxes) {
  std::string text;
  int k = 0;
  char line[160];
  for (const auto& b : boxes) {
    std::snprintf(line, sizeof line, "%.6f %d %s %.1f %.1f %.1f %.1f %.3f %d\n", stamp, k++,
                  b.label.empty() ? "person" : b.label.c_str(), b.rect.x, b.rect.y, b.rect.x + b.rect.width,
                  b.rect.y + b.rect.height, b.score, b.tracked ? 1 : 0);
    text += line;
  }
  return text;
}

// Retention counts static keypoints inside the boxes this run used (none in modes off and
// geometry); exact synthetic masks need no ignored border. The frame's metrics, none without a
// mask.
std::optional<screening::ScreeningMetrics> evaluateFrame(const slam::System& system, const Prepared& p,
                                                         MetricsAccumulator& metrics) {
  if (p.mask.empty()) return std::nullopt;
  try {
    const screening::ScreeningMetrics m =
        screening::evaluateScreening(system.lastFrame(), p.mask, system.lastBoxes(), 0);
    metrics.sum += m;
    ++metrics.frames;
    return m;
  } catch (const Error& e) {
    std::fprintf(stderr, "\nwarning: %s: %s (frame not evaluated)\n", p.mask_path.c_str(), e.what());
    return std::nullopt;
  }
}

const char* kFramesHeader =
    "# rgb_stamp index state inliers keypoints dynamic boxes box_age keyframe person_keypoints "
    "person_dropped static_keypoints static_dropped latency_ms\n";

// Milliseconds from the frame's arrival (the camera's instant with --camera-rate or --realtime,
// else when it was read) to now.
double msSinceArrival(const Prepared& p) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - p.arrival).count();
}

// One line of frames.txt: how tracking and screening went in this frame, to find where a run
// went wrong (the four screening counts are -1 without a ground-truth mask; latency_ms from the
// frame's arrival to its pose, -1 without one).
std::string frameLine(const Prepared& p, const char* state, const slam::TrackResult* r,
                      const slam::System* system, const std::optional<screening::ScreeningMetrics>& m,
                      double latency_ms) {
  long keypoints = 0, dynamic = 0, boxes = 0;
  if (system) {
    const features::FeatureFrame& f = system->lastFrame();
    keypoints = static_cast<long>(f.keypoints.size());
    dynamic = static_cast<long>(std::count_if(f.dynamic.begin(), f.dynamic.end(), [](auto d) { return d != 0; }));
    boxes = static_cast<long>(system->lastBoxes().size());
  }
  // Frames between the detected image and this one: 0 its own boxes, -1 no new detection.
  const long box_age = p.detected_image >= 0 ? static_cast<long>(p.index) - p.detected_image : -1;
  char line[256];
  std::snprintf(line, sizeof line, "%.6f %zu %s %d %ld %ld %ld %ld %d %d %d %d %d %.1f\n", p.stamp, p.index, state,
                r ? r->inliers : 0, keypoints, dynamic, boxes, box_age,
                r && r->keyframe_inserted ? 1 : 0, m ? m->person_total : -1, m ? m->person_dropped : -1,
                m ? m->static_total : -1, m ? m->static_dropped : -1, latency_ms);
  return line;
}

// Async detection (the frame was offered to the detector as it arrived, detectInto): screens
// the frame with the newest result of it or an earlier frame if that is fresh and recent;
// otherwise with no detection (the box tracker carries earlier boxes).
void attachAsyncBoxes(const RunSetup& setup, detection::BoxFeed& feed, Prepared& p, slam::System& system,
                      LoopResult& res) {
  if (!setup.async || !p.has_image) return;
  const long index = static_cast<long>(p.index);
  if (setup.max_lag_frames > 0) setup.async->waitForFrameIn(index - setup.max_lag_frames, index, p.bgr, p.stamp);
  const std::optional<detection::DetectionResult> newest = setup.async->newestUpTo(index);
  const long expired_before = feed.expired();
  const detection::FrameBoxes fb = feed.take(newest, p.stamp);
  res.boxes_expired += feed.expired() - expired_before;
  p.detector_ran = fb.fresh;
  if (!fb.fresh) return;
  p.detected_image = fb.source_frame;
  ++res.boxes_fresh;
  p.boxes = fb.boxes;
  system.recordDetectionTime(newest->ms);
  if (!newest->error.empty()) p.warning += (p.warning.empty() ? "" : "; ") + ("detector failed: " + newest->error);
}

// The files the frame loop grows (io::RunFiles): poses as tracked, boxes as screened.
struct PartialOutputs {
  std::unique_ptr<io::IncrementalFile> trajectory;
  std::unique_ptr<io::IncrementalFile> boxes;  // modes with detection only
  std::unique_ptr<io::IncrementalFile> frames;
};

bool depthUnusable(const Prepared& p) {
  return p.depth.empty() || p.depth.channels() != 1 || p.depth.size() != p.bgr.size() ||
         cv::countNonZero(p.depth > 0) == 0;
}

// The first frame of each kind gets a warning; the rest are counted for the summary.
void countUntracked(const slam::System& system, const Prepared& p, UntrackedCounts& c) {
  auto first = [&p](size_t& n, const char* why) {
    if (n++ == 0)
      std::fprintf(stderr, "\nwarning: frame %zu (%.6f): %s; frames like it are counted in the summary\n", p.index,
                   p.stamp, why);
  };
  if (depthUnusable(p))
    first(c.no_depth, "no usable depth (missing, no valid pixel, or not the size of the image)");
  else if (system.lastFrame().keypoints.empty())
    first(c.no_keypoints, "no keypoint found (black, blank or saturated image?)");
  else
    ++c.lost;
}

void trackFrame(slam::System& system, Prepared& p, PartialOutputs& outputs, LoopResult& res) {
  if (!p.warning.empty()) std::fprintf(stderr, "\nwarning: frame %zu (%.6f): %s\n", p.index, p.stamp, p.warning.c_str());
  if (p.detection_ms >= 0) system.recordDetectionTime(p.detection_ms);
  if (!p.has_image) {
    ++res.skipped;
    ++res.untracked.no_image;
    outputs.frames->append(frameLine(p, "no_image", nullptr, nullptr, std::nullopt, -1));
    return;
  }
  const slam::TrackResult r = p.extracted ? system.trackExtracted(std::move(*p.extracted), p.boxes, p.detector_ran)
                                           : system.trackRgbd(p.bgr, p.depth, p.stamp, p.boxes, p.detector_ran);
  const double latency_ms = msSinceArrival(p);
  if (r.state == slam::TrackingState::Ok) {
    outputs.trajectory->append(io::formatTumPose(StampedPose{p.stamp, r.T_wc}));
  } else {
    ++res.lost_reports;
    countUntracked(system, p, res.untracked);
  }
  ++res.processed;
  if (outputs.boxes) outputs.boxes->append(screenedBoxLines(p.stamp, system.lastBoxes()));
  const std::optional<screening::ScreeningMetrics> m = evaluateFrame(system, p, res.metrics);
  outputs.frames->append(frameLine(p, slam::toString(r.state), &r, &system, m, latency_ms));
}

template <class Source>
void runFrameLoop(Source& source, const RunSetup& setup, slam::System& system, PartialOutputs& outputs,
                  LoopResult& res) {
  ProgressBar bar("yolo_slam_run", setup.frames);
  detection::BoxFeed feed(setup.max_box_age_s);
  while (!stopRequested()) {
    Stopwatch fsw;
    std::optional<Prepared> p = source.next();
    if (!p) break;
    attachAsyncBoxes(setup, feed, *p, system, res);
    trackFrame(system, *p, outputs, res);
    res.frame_ms.push_back(fsw.ms());
    res.latency_ms.push_back(msSinceArrival(*p));
    char extra[96];
    std::snprintf(extra, sizeof extra, "%s, lost %zu", slam::toString(system.state()), res.lost_reports);
    bar.update(p->index + 1, extra);
  }
  bar.finish();
}

// One stage of the frame pipeline on a worker of its own: takes the frames of `source` in
// order and does `work` on each frame with an image, one frame ahead of its caller.
template <class Source>
class AheadStage {
 public:
  using Work = std::function<void(Prepared&)>;
  AheadStage(Source& source, const char* thread_name, Work work)
      : source_(source), thread_name_(thread_name), work_(std::move(work)) {
    start();
  }
  ~AheadStage() {
    if (next_.valid()) next_.wait();
  }
  AheadStage(const AheadStage&) = delete;
  AheadStage& operator=(const AheadStage&) = delete;
  std::optional<Prepared> next() {
    std::optional<Prepared> p = next_.get();
    if (p) start();
    return p;
  }

 private:
  void start() {
    next_ = std::async(std::launch::async, [this] {
      nameThisThread(thread_name_);
      std::optional<Prepared> p = source_.next();
      if (p && p->has_image) work_(*p);
      return p;
    });
  }
  Source& source_;
  const char* const thread_name_;
  const Work work_;
  std::future<std::optional<Prepared>> next_;
};

// The pipeline's stages, each on its own worker: the source loads (or the camera hands over)
// frame t+2 while frame t+1 is detected (every-frame detection, or boxes read from a file) and,
// unless --sequential, frame t+1 is then extracted (System::extractFrame) while the frame loop
// screens and tracks frame t. With --sequential the frame loop extracts, so the feature budget
// follows the frame just screened and two runs are identical. The asynchronous detector is
// offered a frame in the detection stage, as the frame arrives (a camera's detector sees the
// newest image, not the one being screened); Detection.asyncMaxLag counts frames screened.
template <class Source>
void runFrames(Source& source, const RunSetup& setup, slam::System& system, PartialOutputs& outputs,
               LoopResult& res) {
  AheadStage<Source> detect(source, "ys_detect_frame", [&setup](Prepared& p) { detectInto(setup, p); });
  if (system.sequential()) {
    runFrameLoop(detect, setup, system, outputs, res);
    return;
  }
  AheadStage<AheadStage<Source>> extract(detect, "ys_extract", [&system](Prepared& p) {
    p.extracted = system.extractFrame(p.bgr, p.depth, p.stamp);
  });
  runFrameLoop(extract, setup, system, outputs, res);
}

LoopResult processFrames(const Args& args, const RunSetup& setup, slam::System& system, PartialOutputs& outputs) {
  LoopResult res;
  Stopwatch total;
  if (args.camera_rate) {
    warnAboutStampGaps(setup, "--camera-rate");
    CameraSource feed(setup);
    total.restart();  // reading the frames up front is not the pipeline's time
    runFrames(feed, setup, system, outputs, res);
    res.camera_offered = feed.offered();
    res.camera_dropped = feed.dropped();
  } else {
    if (args.realtime) warnAboutStampGaps(setup, "--realtime");
    std::vector<Prepared> preloaded;
    if (args.preload) preloaded = loadAllFrames(setup, "--preload");
    total.restart();  // reading the frames up front is not the pipeline's time
    PrefetchSource source(setup, args.realtime, std::move(preloaded));
    runFrames(source, setup, system, outputs, res);
  }
  if (setup.async) setup.async->waitIdle();
  res.total_s = total.ms() / 1000.0;
  return res;
}

struct AteSummary {
  double rmse = NAN;
  size_t pairs = 0;
};

AteSummary ateOf(const io::TumSequence& seq, const Trajectory& traj) {
  AteSummary a;
  if (!seq.hasGroundTruth() || traj.size() < 2) return a;
  try {
    const eval::AteResult ate = eval::computeAte(seq.groundTruth(), traj);
    a.rmse = ate.stats.rmse;
    a.pairs = ate.stats.count;
  } catch (const Error& e) {
    std::fprintf(stderr, "warning: ATE not computed: %s\n", e.what());
  }
  return a;
}

// How the boxes were had: every frame, or asynchronously (frames given a new result, results
// dropped for age, what the detector did).
Json detectionJson(const RunSetup& setup, const LoopResult& res) {
  if (!setup.stages.detection) return nullptr;
  if (!setup.async) return Json{{"mode", setup.detector ? "every-frame" : "file"}};
  const detection::AsyncDetectionCounts c = setup.async->counts();
  return Json{{"mode", "async"},           {"max_age_s", setup.max_box_age_s},
              {"offered", c.offered},      {"detected", c.detected},
              {"replaced", c.replaced},    {"throttled", c.throttled},
              {"reoffered", c.reoffered},
              {"frames_with_new_boxes", res.boxes_fresh},
              {"results_too_old", res.boxes_expired}};
}

// The map files of a run (--load-map, --save-map), for stats.json "map_file".
struct MapFiles {
  std::optional<slam::MapFileInfo> loaded, saved;
};

Json mapFileInfoJson(const std::string& path, const std::optional<slam::MapFileInfo>& info) {
  if (!info) return nullptr;
  return Json{{"path", path},           {"bytes", info->bytes},
              {"keyframes", info->keyframes}, {"map_points", info->map_points},
              {"ms", jsonNumber(info->ms)}};
}

Json mapFilesJson(const Args& args, const MapFiles& maps) {
  return Json{{"localization", args.localization},
              {"loaded", mapFileInfoJson(args.load_map, maps.loaded)},
              {"saved", mapFileInfoJson(args.save_map, maps.saved)}};
}

// How a run ended: stats.json "complete", "status" and "reason", and the exit code.
struct Outcome {
  std::string status;  // "finished", "interrupted" or "too few frames tracked"
  std::string reason;  // why the run is not complete; empty when it is
  int exit_code = 0;
  size_t frames = 0, tracked = 0;  // frames given to the pipeline, frames with a pose
  double tracked_fraction = 0;
  bool complete() const { return reason.empty(); }
};

std::string signalName(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "signal " + std::to_string(sig);
  }
}

std::string untrackedSummary(const Outcome& o, const UntrackedCounts& u) {
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "tracked %zu of %zu frames (%.1f%%): %zu without an image, %zu without usable depth, %zu without "
                "keypoints, %zu lost",
                o.tracked, o.frames, 100.0 * o.tracked_fraction, u.no_image, u.no_depth, u.no_keypoints, u.lost);
  return buf;
}

Outcome outcomeOf(const Args& args, const LoopResult& res, const slam::SystemStats& s) {
  Outcome o;
  o.frames = res.processed + res.skipped;
  o.tracked = s.tracked;
  o.tracked_fraction = o.frames > 0 ? static_cast<double>(o.tracked) / o.frames : 0.0;
  if (g_stop != 0) {
    o.status = "interrupted";
    o.reason = "stopped by " + signalName(g_stop) + " after " + std::to_string(o.frames) + " frames";
    o.exit_code = kExitSignalBase + g_stop;
  } else if (o.tracked_fraction < args.min_tracked) {
    o.status = "too few frames tracked";
    char buf[96];
    std::snprintf(buf, sizeof buf, " (below --min-tracked %g)", args.min_tracked);
    o.reason = untrackedSummary(o, res.untracked) + buf;
    o.exit_code = kExitTooFewTracked;
  } else {
    o.status = "finished";
  }
  return o;
}

// stats.json while the run goes on: what a reader finds after a kill (SIGKILL, a crash).
Json runningStatsJson(const Args& args) {
  return Json{{"complete", false},
              {"status", "running"},
              {"reason", std::string("the run has not finished: it is still going, or it was killed or failed "
                                     "before writing its results; ") +
                             io::RunFiles::kPartialTrajectory + " holds the tracking poses estimated so far"},
              {"sequence", args.sequence},
              {"config", args.config},
              {"pid", static_cast<long>(::getpid())},
              {"files", Json{{"partial_trajectory", io::RunFiles::kPartialTrajectory}}}};
}

// Which files belong to this run (written before stats.json; paths relative to OUT, the map
// as given).
Json runFilesJson(const Args& args, bool boxes_written, bool frames_written) {
  return Json{{"camera_trajectory", io::RunFiles::kCameraTrajectory},
              {"keyframe_trajectory", io::RunFiles::kKeyFrameTrajectory},
              {"boxes_screened", boxes_written ? Json(io::RunFiles::kBoxesScreened) : Json(nullptr)},
              {"frames", frames_written ? Json(io::RunFiles::kFrames) : Json(nullptr)},
              {"map", args.save_map.empty() ? Json(nullptr) : Json(args.save_map)}};
}

// Takes the folder for this run before the first frame: the previous run's files go (a folder
// never mixes two runs), stats.json says "running", and the partial files are opened.
PartialOutputs claimRunFolder(const Args& args, const RunSetup& setup) {
  io::removePreviousRun(args.out);
  io::writeFileAtomic(joinPath(args.out, io::RunFiles::kStats), dumpJson(runningStatsJson(args)));
  PartialOutputs p;
  p.trajectory = std::make_unique<io::IncrementalFile>(joinPath(args.out, io::RunFiles::kPartialTrajectory),
                                                       io::kTumTrajectoryHeader);
  if (setup.stages.detection)
    p.boxes = std::make_unique<io::IncrementalFile>(joinPath(args.out, io::RunFiles::kPartialBoxes),
                                                    "# rgb_stamp index label x1 y1 x2 y2 score tracked\n");
  p.frames = std::make_unique<io::IncrementalFile>(joinPath(args.out, io::RunFiles::kPartialFrames), kFramesHeader);
  return p;
}

// The final stats.json: the completion marker and the run's files first, then the figures.
struct FinalStats {
  const Outcome& outcome;
  const LoopResult& res;
  size_t poses;
  const AteSummary& ate;
  const slam::SystemStats& s;
  const MapFiles& maps;
  bool boxes_written;
  bool frames_written;
};

Json trackingJson(const Args& args, const FinalStats& f) {
  return Json{{"frames_read", f.outcome.frames},
              {"tracked_fraction", jsonNumber(f.outcome.tracked_fraction)},
              {"min_tracked", args.min_tracked},
              {"untracked", f.res.untracked.json()}};
}

Json runStatsJson(const Args& args, const RunSetup& setup, const FinalStats& f) {
  const screening::Stages& st = setup.stages;
  const LoopResult& res = f.res;
  Json j{{"complete", f.outcome.complete()},
         {"status", f.outcome.status},
         {"reason", f.outcome.reason},
         {"files", runFilesJson(args, f.boxes_written, f.frames_written)},
         {"sequence", args.sequence},
         {"config", args.config},
         {"dynamic_mode", screening::toString(setup.options.screening.mode)},
         {"boxes", setup.boxes_source},
         {"interrupted", g_stop != 0},
         {"signal", g_stop != 0 ? Json(signalName(g_stop)) : Json(nullptr)},
         {"tracking", trackingJson(args, f)},
         {"frames_skipped", res.skipped},
         {"trajectory_poses", f.poses},
         {"ate_rmse_m", jsonNumber(f.ate.rmse)},
         {"ate_pairs", f.ate.pairs},
         {"wall_time_s", jsonNumber(res.total_s)},
         {"frames_preloaded", args.preload || args.camera_rate},
         {"fps", jsonNumber(res.fps())}};
  j.update(slam::statsCountsJson(f.s));
  j["track_boxes"] = st.box_tracking;
  j["propagate_labels"] = st.label_propagation;
  j["static_box_veto"] = st.static_box_veto;
  j["motion_screening"] = st.motion_screening;
  j["sequential"] = setup.options.sequential;
  j["vocabulary"] = args.vocabulary;
  j["screening_metrics"] = res.metrics.json();
  j["timings"] = slam::statsTimingsJson(f.s, {{"frame", res.frame_ms}, {"latency", res.latency_ms}});
  j["detection"] = detectionJson(setup, res);
  j["map_file"] = mapFilesJson(args, f.maps);
  if (args.camera_rate)
    j["camera"] = Json{{"offered", res.camera_offered},
                       {"processed", res.processed + res.skipped},
                       {"dropped", res.camera_dropped},
                       {"processed_fraction", jsonRatio(static_cast<long>(res.processed + res.skipped), res.camera_offered)},
                       {"latency_ms", summaryJsonMs(summarize(res.latency_ms))}};
  j["overrides"] = setup.cfg.overrides();
  j["settings"] = setup.cfg.effective();
  return j;
}

void printSummary(const RunSetup& setup, const LoopResult& res, const AteSummary& ate, const slam::SystemStats& s) {
  std::printf("frames %zu, tracked %zu, lost %zu, keyframes %zu, map points %zu\n", s.frames, s.tracked, s.lost,
              s.keyframes, s.map_points);
  const auto t = summarize(slam::extractionPlusTrackingMs(s));
  std::printf("extraction+tracking median %.2f ms, p95 %.2f ms; %.1f frames/s overall\n", t.median, t.p95, res.fps());
  if (std::isfinite(ate.rmse)) std::printf("ATE RMSE %.4f m over %zu poses\n", ate.rmse, ate.pairs);
  const screening::ScreeningMetrics& m = res.metrics.sum;
  if (res.metrics.frames > 0)
    std::printf("screening vs masks over %zu frames: dynamic recall %s (on people %s), static retention "
                "in boxes %s, static dropped %s (%s off people's outlines)\n",
                res.metrics.frames, percent(m.dynamic_dropped, m.dynamic_total).c_str(),
                percent(m.person_dropped, m.person_total).c_str(),
                percent(m.static_in_boxes_kept, m.static_in_boxes).c_str(),
                percent(m.static_dropped, m.static_total).c_str(),
                percent(m.static_dropped - m.static_on_outline_dropped, m.static_total - m.static_on_outline).c_str());
  if (setup.stages.box_tracking)
    std::printf("boxes screened: %ld from the detector, %ld carried by the box tracker\n", s.boxes.detected,
                s.boxes.tracked);
  if (setup.stages.label_propagation)
    std::printf("label propagation marked %d keypoints dynamic\n", s.temporal.propagated);
  if (setup.stages.static_box_veto)
    std::printf("static-box veto: %d boxes left alone, %d screened keypoints kept\n", s.temporal.boxes_vetoed,
                s.temporal.vetoed);
  if (setup.stages.motion_screening)
    std::printf("motion screening marked %d keypoints dynamic\n", s.temporal.motion_dropped);
  if (res.metrics.frames > 0)
    std::printf("dynamic keypoints outside every box: %ld, %s dropped\n", static_cast<long>(m.dynamic_outside_boxes),
                percent(m.dynamic_outside_dropped, m.dynamic_outside_boxes).c_str());
}

// The dense map's files (--octomap, --cloud) after shutdown, and its stats.json object (null
// when the dense map is off).
Json writeDenseMap(const Args& args, const slam::System& system) {
  const mapping::DenseMapper* dense = system.denseMap();
  if (!dense) return nullptr;
  if (!args.octomap.empty()) dense->writeOctomap(args.octomap);
  if (!args.cloud.empty()) dense->writeCloud(args.cloud);
  const mapping::DenseMapStats d = dense->stats();
  std::printf("dense map: %zu keyframes, %zu occupied voxels, %zu cloud points, %.1f MB\n", d.keyframes, d.voxels,
              d.points, d.memory_bytes / (1024.0 * 1024.0));
  Json j = d;
  j["octomap"] = args.octomap.empty() ? Json(nullptr) : Json(args.octomap);
  j["cloud"] = args.cloud.empty() ? Json(nullptr) : Json(args.cloud);
  return j;
}

// The end of a run, in an order that a kill at any point leaves readable (README "What happens
// when things go wrong"): the final trajectories (each atomic), the boxes renamed into place,
// the map files (--save-map, then --octomap and --cloud), then stats.json, the completion
// marker, and last the partial trajectory goes.
int finishRun(const Args& args, const RunSetup& setup, slam::System& system, PartialOutputs& outputs,
              const LoopResult& res, MapFiles& maps) {
  system.waitForLocalMapping();
  system.shutdown();
  const Trajectory traj = system.cameraTrajectory();
  io::writeTrajectory(joinPath(args.out, io::RunFiles::kCameraTrajectory), traj);
  io::writeTrajectory(joinPath(args.out, io::RunFiles::kKeyFrameTrajectory), system.keyframeTrajectory());
  const bool boxes_written = outputs.boxes && outputs.boxes->finishAs(joinPath(args.out, io::RunFiles::kBoxesScreened));
  const bool frames_written = outputs.frames->finishAs(joinPath(args.out, io::RunFiles::kFrames));
  if (!args.save_map.empty()) {
    maps.saved = system.saveMap(args.save_map);
    std::printf("saved map %s: %zu keyframes, %zu points, %zu bytes in %.0f ms\n", args.save_map.c_str(),
                maps.saved->keyframes, maps.saved->map_points, maps.saved->bytes, maps.saved->ms);
  }
  const Json dense = writeDenseMap(args, system);
  const AteSummary ate = ateOf(setup.seq, traj);
  const slam::SystemStats s = system.stats();
  const Outcome outcome = outcomeOf(args, res, s);
  const FinalStats stats{outcome, res, traj.size(), ate, s, maps, boxes_written, frames_written};
  Json stats_json = runStatsJson(args, setup, stats);
  if (!dense.is_null()) stats_json["dense_map"] = dense;
  io::writeFileAtomic(joinPath(args.out, io::RunFiles::kStats), dumpJson(stats_json));
  outputs.trajectory->remove();
  printSummary(setup, res, ate, s);
  const std::string boxes_name = boxes_written ? std::string(io::RunFiles::kBoxesScreened) + "," : "";
  const std::string frames_name = frames_written ? std::string(io::RunFiles::kFrames) + "," : "";
  std::printf("wrote %s/{%s,%s,%s%s%s}\n", args.out.c_str(), io::RunFiles::kCameraTrajectory,
              io::RunFiles::kKeyFrameTrajectory, boxes_name.c_str(), frames_name.c_str(), io::RunFiles::kStats);
  if (outcome.exit_code == kExitTooFewTracked)
    std::fprintf(stderr, "error: %s; everything is written to %s (exit code %d; --min-tracked 0 accepts such a run)\n",
                 outcome.reason.c_str(), args.out.c_str(), kExitTooFewTracked);
  return outcome.exit_code;
}

int run(const Args& args) {
  RunSetup setup = setUp(args);
  slam::System system(setup.cam, setup.options, setup.voc);
  MapFiles maps;
  // Localization first: local mapping is paused before the loaded map can get a keyframe.
  if (args.localization) system.setLocalizationOnly(true);
  if (!args.load_map.empty()) {
    maps.loaded = system.loadMap(args.load_map);
    std::fprintf(stderr, "yolo_slam_run: loaded map %s: %zu keyframes, %zu points in %.0f ms\n", args.load_map.c_str(),
                 maps.loaded->keyframes, maps.loaded->map_points, maps.loaded->ms);
  }
  installSignalHandlers();
  PartialOutputs outputs = claimRunFolder(args, setup);
  // Printed once the handlers are in place and the folder is claimed (the signal tests wait
  // for this line).
  std::fprintf(stderr, "yolo_slam_run: %zu frames from %s, dynamic mode %s, boxes: %s, vocabulary: %s%s\n",
               setup.frames, args.sequence.c_str(), screening::toString(setup.options.screening.mode).c_str(),
               setup.boxes_source.c_str(), args.vocabulary.empty() ? "none (no BoW)" : args.vocabulary.c_str(),
               setup.has_masks ? ", screening metrics from masks/" : "");

  const LoopResult res = processFrames(args, setup, system, outputs);
  if (g_stop)
    std::fprintf(stderr, "interrupted by %s: stopping after %zu frames and writing the results\n",
                 signalName(g_stop).c_str(), res.processed + res.skipped);
  return finishRun(args, setup, system, outputs, res, maps);
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
    return kExitError;
  } catch (const cv::Exception& e) {
    std::fprintf(stderr, "error: OpenCV: %s\n", e.what());
    return kExitError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitError;
  }
}
