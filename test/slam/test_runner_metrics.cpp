// yolo_slam_run on a short synthetic walking_xyz sequence (sim library, written to a temp
// folder): screening metrics against the masks in stats.json, corrupt/missing masks, default
// and explicit vocabulary/config handling, and Ctrl-C (SIGINT to the running child) still
// writing the trajectory so far, a valid stats.json and the map (--save-map); a saved map loaded
// for localization (--load-map, --localization) and bad map files.
#include "yolo_slam/common/json.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/sim/generator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace yolo_slam;
namespace fs = std::filesystem;

namespace {

std::string tool() { return joinPath(YOLO_SLAM_BIN_DIR, "yolo_slam_run"); }

std::string readAll(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

size_t lineCount(const std::string& path) {
  std::ifstream f(path);
  size_t n = 0;
  for (std::string l; std::getline(f, l);)
    if (!l.empty() && l[0] != '#') ++n;
  return n;
}

// OUT/stats.json, parsed.
Json statsOf(const std::string& out) {
  const std::string path = joinPath(out, "stats.json");
  return parseJson(readAll(path), path);
}

// The number at `key` of a JSON object; NaN if absent or not a number.
double numberOf(const Json& j, const std::string& key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : NAN;
}

// A started child with stdout/stderr redirected to files.
struct Child {
  pid_t pid = -1;
  std::string out_path, err_path;
};

Child spawn(const std::vector<std::string>& args, const std::string& log_prefix) {
  Child c;
  c.out_path = log_prefix + ".out";
  c.err_path = log_prefix + ".err";
  std::vector<char*> argv;
  std::vector<std::string> all = {tool()};
  all.insert(all.end(), args.begin(), args.end());
  for (auto& a : all) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  c.pid = ::fork();
  if (c.pid == 0) {
    const int o = ::open(c.out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = ::open(c.err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(o, 1);
    ::dup2(e, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return c;
}

int waitExit(const Child& c) {
  int status = 0;
  if (::waitpid(c.pid, &status, 0) != c.pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int runTool(const std::vector<std::string>& args, const std::string& log_prefix, std::string& out,
            std::string& err) {
  Child c = spawn(args, log_prefix);
  const int rc = waitExit(c);
  out = readAll(c.out_path);
  err = readAll(c.err_path);
  return rc;
}

class RunnerMetrics : public ::testing::Test {
 protected:
  static constexpr int kFrames = 30;
  static std::string dir_;  // temp root; dir_/seq is the synthetic sequence

  static void SetUpTestSuite() {
    char tmpl[] = "/tmp/ys_runner_metrics_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    sim::SynthOptions so;
    so.preset = "walking_xyz";
    so.seed = 1;
    so.frames = kFrames;
    sim::SequenceGenerator(so).generate(joinPath(dir_, "seq"));
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
  }
  void SetUp() override {
    if (!fileExists(tool())) GTEST_SKIP() << tool() << " not built (make yolo_slam_run)";
  }
  static std::string seq() { return joinPath(dir_, "seq"); }
};
std::string RunnerMetrics::dir_;

}  // namespace

TEST_F(RunnerMetrics, GroundTruthBoxesGiveHighRecall) {
  const std::string out = joinPath(dir_, "out_gt");
  std::string so, se;
  // Default --config (SEQ/camera.yaml) and default vocabulary.
  ASSERT_EQ(runTool({"--sequence", seq(), "--out", out, "--boxes-from-gt"}, joinPath(dir_, "gt"), so, se), 0)
      << so << se;
  EXPECT_NE(se.find("vocab/yolo_slam_orb_k10_L4.vocab"), std::string::npos) << se;
  EXPECT_NE(so.find("dynamic recall"), std::string::npos) << so;
  const Json js = statsOf(out);
  const Json m = js["screening_metrics"];
  ASSERT_TRUE(m.is_object()) << js.dump();
  EXPECT_EQ(numberOf(m, "frames"), kFrames) << m.dump();
  const double dyn = numberOf(m, "dynamic_keypoints"), dropped = numberOf(m, "dropped");
  EXPECT_GT(dyn, 100) << m.dump();  // people fill a good part of walking_xyz frames
  EXPECT_LE(dropped, dyn) << m.dump();
  const double recall = numberOf(m, "dynamic_recall");
  EXPECT_NEAR(recall, dropped / dyn, 1e-3) << m.dump();
  EXPECT_GT(recall, 0.5) << m.dump();
  const double sib = numberOf(m, "static_in_boxes"), kept = numberOf(m, "kept");
  EXPECT_GT(sib, 0) << m.dump();
  EXPECT_LE(kept, sib) << m.dump();
  const double retention = numberOf(m, "static_retention");
  EXPECT_NEAR(retention, kept / sib, 1e-3) << m.dump();
  EXPECT_GE(retention, 0.0);
  EXPECT_LE(retention, 1.0);
  // Detection/screening time and keypoint counts of the screening itself.
  const Json kp = js["keypoints"];
  EXPECT_GT(numberOf(kp, "in_boxes"), 0) << kp.dump();
  EXPECT_EQ(numberOf(kp, "in_boxes"), numberOf(kp, "kept") + numberOf(kp, "dropped")) << kp.dump();
  EXPECT_GT(numberOf(js["timings"]["screening"], "count"), 0) << js.dump();
  EXPECT_TRUE(js["timings"]["detection"].is_object()) << js.dump();  // no detector ran: count 0
  EXPECT_EQ(lineCount(joinPath(out, "CameraTrajectory.txt")), numberOf(js, "trajectory_poses"));
}

// frames.txt: one line per frame read, in order, with the tracking state and, on a synthetic
// sequence, the screening counts of the frame's ground-truth mask.
TEST_F(RunnerMetrics, FramesFileHasALinePerFrame) {
  const std::string out = joinPath(dir_, "out_frames");
  std::string so, se;
  ASSERT_EQ(runTool({"--sequence", seq(), "--out", out, "--boxes-from-gt", "--sequential"}, joinPath(dir_, "frames"),
                    so, se),
            0)
      << so << se;
  std::istringstream in(readAll(joinPath(out, "frames.txt")));
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line.rfind("# rgb_stamp index state inliers", 0), 0u) << line;
  size_t n = 0, ok = 0;
  long persons = 0, persons_dropped = 0;
  while (std::getline(in, line)) {
    std::istringstream is(line);
    double stamp = 0;
    size_t index = 0;
    std::string state;
    long v[10];
    ASSERT_TRUE(is >> stamp >> index >> state) << line;
    for (long& x : v) ASSERT_TRUE(is >> x) << line;
    double latency_ms = -1;
    ASSERT_TRUE(is >> latency_ms) << line;
    EXPECT_GT(latency_ms, 0.0) << line;
    EXPECT_EQ(index, n) << line;
    EXPECT_TRUE(state == "ok" || state == "lost" || state == "not_initialized") << line;
    ok += state == "ok" ? 1 : 0;
    EXPECT_GE(v[1], v[2]) << "dynamic keypoints are keypoints: " << line;
    EXPECT_GE(v[6], 0) << "the synthetic sequence has masks: " << line;
    EXPECT_EQ(v[4], 0) << "every frame's own boxes (--boxes-from-gt): " << line;
    persons += v[6];
    persons_dropped += v[7];
    ++n;
  }
  EXPECT_EQ(static_cast<int>(n), kFrames);
  const Json js = statsOf(out);
  EXPECT_EQ(js["files"]["frames"], "frames.txt") << js.dump();
  EXPECT_GT(persons_dropped, 0);
  EXPECT_EQ(static_cast<long>(ok), js["tracked"].get<long>()) << js.dump();
  EXPECT_EQ(persons, js["screening_metrics"]["person_keypoints"].get<long>()) << js.dump();
  EXPECT_EQ(persons_dropped, js["screening_metrics"]["person_dropped"].get<long>()) << js.dump();
}

// The detector's rows of a boxes_screened.txt (tracked 0), with the header dropped.
static std::vector<std::string> detectedRows(const std::string& path) {
  std::vector<std::string> rows;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#' && line.size() > 2 && line.compare(line.size() - 2, 2, " 0") == 0)
      rows.push_back(line);
  return rows;
}

TEST_F(RunnerMetrics, ReplayedBoxesAreTheBoxesOfTheFirstRun) {
  const std::string first = joinPath(dir_, "out_replay_src"), second = joinPath(dir_, "out_replay");
  std::string so, se;
  ASSERT_EQ(runTool({"--sequence", seq(), "--out", first, "--boxes-from-gt", "--no-vocabulary", "--max-frames", "8"},
                    joinPath(dir_, "replay_src"), so, se),
            0)
      << so << se;
  const std::vector<std::string> want = detectedRows(joinPath(first, "boxes_screened.txt"));
  ASSERT_GT(want.size(), 4u);
  const std::string replay = joinPath(first, "boxes_screened.txt");
  ASSERT_EQ(runTool({"--sequence", seq(), "--out", second, "--boxes", replay, "--no-vocabulary", "--max-frames", "8"},
                    joinPath(dir_, "replay"), so, se),
            0)
      << so << se;
  EXPECT_NE(se.find("boxes: " + replay), std::string::npos) << se;
  EXPECT_EQ(detectedRows(joinPath(second, "boxes_screened.txt")), want);
  const Json js = statsOf(second);
  EXPECT_EQ(numberOf(js["boxes_screened"], "detected"), static_cast<double>(want.size())) << js.dump();

  // A file in the other format (boxes.txt has no score/tracked columns): the error names it.
  ASSERT_NE(runTool({"--sequence", seq(), "--out", second, "--boxes", joinPath(seq(), "boxes.txt"),
                     "--no-vocabulary", "--max-frames", "2"},
                    joinPath(dir_, "replay_bad"), so, se),
            0);
  EXPECT_NE(se.find(joinPath(seq(), "boxes.txt")), std::string::npos) << se;
  EXPECT_NE(se.find("score tracked"), std::string::npos) << se;
  ASSERT_NE(runTool({"--sequence", seq(), "--out", second, "--boxes", replay, "--boxes-from-gt"},
                    joinPath(dir_, "replay_both"), so, se),
            0);
  EXPECT_NE(se.find("exclude each other"), std::string::npos) << se;
}

TEST_F(RunnerMetrics, ModeOffDropsNothing) {
  const std::string out = joinPath(dir_, "out_off");
  std::string so, se;
  ASSERT_EQ(runTool({"--sequence", seq(), "--out", out, "--dynamic-mode", "off", "--no-vocabulary",
                     "--max-frames", "10", "--set", "ORBextractor.nFeatures=600"},
                    joinPath(dir_, "off"), so, se),
            0)
      << so << se;
  EXPECT_NE(se.find("vocabulary: none"), std::string::npos) << se;
  // The overrides and every setting the run read, as it used them.
  const Json js = statsOf(out);
  EXPECT_EQ(js["overrides"]["Screening.mode"], "off") << js.dump();
  EXPECT_EQ(js["settings"]["Screening.mode"], "off") << js.dump();
  EXPECT_EQ(js["settings"]["ORBextractor.nFeatures"], 600) << js.dump();
  EXPECT_EQ(js["settings"]["Tracking.minInliers"], 30) << js.dump();  // a default, recorded too
  const Json m = js["screening_metrics"];
  EXPECT_EQ(numberOf(m, "frames"), 10) << m.dump();
  EXPECT_GT(numberOf(m, "dynamic_keypoints"), 0) << m.dump();
  EXPECT_EQ(numberOf(m, "dropped"), 0) << m.dump();
  EXPECT_EQ(numberOf(m, "dynamic_recall"), 0) << m.dump();
  EXPECT_EQ(numberOf(m, "static_dropped"), 0) << m.dump();
  // No box in mode off: retention has no denominator.
  EXPECT_EQ(numberOf(m, "static_in_boxes"), 0) << m.dump();
  EXPECT_TRUE(m["static_retention"].is_null()) << m.dump();
  EXPECT_EQ(js["sequential"], false) << js.dump();
}

// The second run reads every frame up front (--preload): the same frames in the same order.
TEST_F(RunnerMetrics, SequentialRunsWriteIdenticalTrajectories) {
  std::string traj[2];
  for (int k = 0; k < 2; ++k) {
    const std::string out = joinPath(dir_, "out_sequential" + std::to_string(k));
    std::vector<std::string> args{"--sequence", seq(), "--out", out, "--boxes-from-gt", "--sequential"};
    if (k == 1) args.push_back("--preload");
    std::string so, se;
    ASSERT_EQ(runTool(args, joinPath(dir_, "sequential" + std::to_string(k)), so, se), 0) << so << se;
    const Json js = statsOf(out);
    EXPECT_EQ(js["sequential"], true) << js.dump();
    EXPECT_EQ(js["settings"]["System.sequential"], true) << js.dump();
    EXPECT_EQ(js["frames_preloaded"], k == 1) << js.dump();
    traj[k] = readAll(joinPath(out, "CameraTrajectory.txt"));
  }
  EXPECT_FALSE(traj[0].empty());
  EXPECT_EQ(traj[0], traj[1]);
}

TEST_F(RunnerMetrics, CorruptMaskWarnsMissingMaskIsSkipped) {
  // A copy of the first 6 frames' data: mask 2 corrupt, mask 3 missing.
  const std::string s2 = joinPath(dir_, "seq_badmask");
  fs::copy(seq(), s2, fs::copy_options::recursive);
  std::vector<std::string> masks;
  for (const auto& e : fs::directory_iterator(joinPath(s2, "masks"))) masks.push_back(e.path().string());
  std::sort(masks.begin(), masks.end());
  ASSERT_GE(masks.size(), 6u);
  { std::ofstream(masks[2], std::ios::trunc) << "not a png"; }
  fs::remove(masks[3]);
  const std::string out = joinPath(dir_, "out_badmask");
  std::string so, se;
  ASSERT_EQ(runTool({"--sequence", s2, "--out", out, "--boxes-from-gt", "--no-vocabulary", "--max-frames", "6"},
                    joinPath(dir_, "badmask"), so, se),
            0)
      << so << se;
  EXPECT_NE(se.find("warning: "), std::string::npos) << se;
  EXPECT_NE(se.find(masks[2]), std::string::npos) << se;
  EXPECT_EQ(se.find(masks[3]), std::string::npos) << se;
  const Json m = statsOf(out)["screening_metrics"];
  EXPECT_EQ(numberOf(m, "frames"), 4) << m.dump();
}

TEST_F(RunnerMetrics, BadVocabularyAndConfigAreOneLineErrors) {
  std::string so, se;
  EXPECT_EQ(runTool({"--sequence", seq(), "--out", joinPath(dir_, "o"), "--vocabulary", "/nonexistent/v.vocab"},
                    joinPath(dir_, "badvoc"), so, se),
            1);
  EXPECT_EQ(se.rfind("error: /nonexistent/v.vocab", 0), 0u) << se;
  EXPECT_EQ(se.find('\n'), se.size() - 1) << se;
  const std::string empty_seq = joinPath(dir_, "no_camera_yaml");
  fs::create_directories(empty_seq);
  EXPECT_EQ(runTool({"--sequence", empty_seq, "--out", joinPath(dir_, "o")}, joinPath(dir_, "nocfg"), so, se), 1);
  EXPECT_EQ(se.rfind("error: " + joinPath(empty_seq, "camera.yaml"), 0), 0u) << se;
  EXPECT_NE(se.find("--config"), std::string::npos) << se;
}

TEST_F(RunnerMetrics, CtrlCWritesTheFramesDoneSoFar) {
  const std::string out = joinPath(dir_, "out_sigint");
  // --realtime paces the 30 frames over about 1 s, so the signal lands mid-sequence.
  const std::string map = joinPath(dir_, "sigint.ysmap");
  Child c = spawn({"--sequence", seq(), "--out", out, "--boxes-from-gt", "--no-vocabulary", "--realtime", "--save-map",
                   map},
                  joinPath(dir_, "sigint"));
  ASSERT_GT(c.pid, 0);
  // The header line is printed once the signal handlers are installed.
  const auto t0 = std::chrono::steady_clock::now();
  while (readAll(c.err_path).find("yolo_slam_run: ") == std::string::npos &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ::kill(c.pid, SIGINT);
  const int rc = waitExit(c);
  const std::string se = readAll(c.err_path);
  EXPECT_EQ(rc, 130) << se;
  EXPECT_NE(se.find("interrupted"), std::string::npos) << se;
  const size_t poses = lineCount(joinPath(out, "CameraTrajectory.txt"));
  EXPECT_GE(poses, 1u) << se;
  EXPECT_LT(poses, static_cast<size_t>(kFrames)) << se;
  const Json js = statsOf(out);
  ASSERT_TRUE(js.is_object());
  EXPECT_EQ(js["interrupted"], true) << js.dump();
  EXPECT_EQ(numberOf(js, "trajectory_poses"), poses) << js.dump();
  EXPECT_EQ(numberOf(js["map_file"]["saved"], "bytes"), static_cast<double>(fs::file_size(map))) << js.dump();
  const double frames = numberOf(js["screening_metrics"], "frames");
  EXPECT_GE(frames, 1) << js.dump();
  EXPECT_LT(frames, kFrames) << js.dump();
}

// Under ThreadSanitizer the pipeline runs tens of times slower: at camera rate it processes a
// few of the 20 frames and the detector may not finish one before the stream ends. The
// accounting must hold all the same; --min-tracked 0 because tracking is not what is tested.
#ifdef __SANITIZE_THREAD__
constexpr bool kThreadSanitizer = true;
#else
constexpr bool kThreadSanitizer = false;
#endif

TEST_F(RunnerMetrics, CameraRateAndAsyncDetectionAccountForEveryFrame) {
  const std::string out = joinPath(dir_, "out_camera");
  std::string so, se;
  ASSERT_EQ(runTool({"--sequence", seq(), "--out", out, "--camera-rate", "--detection", "async", "--max-frames", "20",
                     "--min-tracked", "0"},
                    joinPath(dir_, "camera"), so, se),
            0)
      << so << se;
  const Json js = statsOf(out);
  const Json cam = js["camera"];
  EXPECT_EQ(cam["offered"], 20) << js.dump();
  EXPECT_EQ(numberOf(cam, "processed") + numberOf(cam, "dropped"), 20) << cam.dump();
  EXPECT_GE(numberOf(cam, "processed"), 1) << cam.dump();
  EXPECT_EQ(numberOf(js, "frames"), numberOf(cam, "processed")) << js.dump();
  EXPECT_EQ(numberOf(js["timings"]["latency"], "count"), numberOf(cam, "processed")) << js.dump();
  // Asynchronous detection: every processed frame was offered to the detector.
  const Json det = js["detection"];
  EXPECT_EQ(det["mode"], "async") << det.dump();
  EXPECT_EQ(numberOf(det, "offered"), numberOf(cam, "processed")) << det.dump();
  EXPECT_EQ(numberOf(det, "offered"), numberOf(det, "detected") + numberOf(det, "replaced")) << det.dump();
  if (!kThreadSanitizer) {
    EXPECT_GE(numberOf(det, "frames_with_new_boxes"), 1) << det.dump();
  }
}

// Full speed with Detection.asyncMaxLag 1: a frame waits until the detector has a result of
// itself or the frame before it. Frames are offered as they arrive, up to two stages ahead of
// the frame being screened (detection, extraction); a frame the detector skipped is offered
// again. A frame never gets a later image's boxes, and each result reaches one frame (the first
// frame gets its own: no frame awaits detection).
TEST_F(RunnerMetrics, AsyncMaxLagBoundsHowOldAFramesBoxesAre) {
  const std::string out = joinPath(dir_, "out_lag");
  std::string so, se;
  ASSERT_EQ(runTool({"--sequence", seq(), "--out", out, "--detection", "async", "--preload", "--max-frames", "12",
                     "--min-tracked", "0", "--set", "Detection.asyncMaxLag=1"},
                    joinPath(dir_, "lag"), so, se),
            0)
      << so << se;
  const Json js = statsOf(out);
  const Json det = js["detection"];
  EXPECT_EQ(numberOf(det, "offered"), 12) << det.dump();
  EXPECT_EQ(numberOf(det, "detected") + numberOf(det, "replaced"), 12 + numberOf(det, "reoffered")) << det.dump();
  // Every other frame at least: each result younger than the lag reaches one frame.
  constexpr long kMaxAge = 1;
  EXPECT_GE(numberOf(det, "detected"), 12 / (kMaxAge + 1)) << det.dump();
  EXPECT_GE(numberOf(det, "frames_with_new_boxes"), 12 / (kMaxAge + 1)) << det.dump();
  EXPECT_EQ(numberOf(js, "awaiting_detection"), 0) << js.dump();
  // frames.txt's box_age: how many frames older the detected image is, never more than the lag.
  std::istringstream in(readAll(joinPath(out, "frames.txt")));
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_NE(line.find(" box_age "), std::string::npos) << line;
  long with_new_boxes = 0;
  while (std::getline(in, line)) {
    std::istringstream is(line);
    std::string stamp, index, state;
    long inliers, keypoints, dynamic, boxes, box_age;
    ASSERT_TRUE(is >> stamp >> index >> state >> inliers >> keypoints >> dynamic >> boxes >> box_age) << line;
    EXPECT_GE(box_age, -1) << line;
    EXPECT_LE(box_age, kMaxAge) << line;
    with_new_boxes += box_age >= 0 ? 1 : 0;
  }
  EXPECT_EQ(with_new_boxes, numberOf(det, "frames_with_new_boxes")) << det.dump();
}

TEST_F(RunnerMetrics, SavedMapIsLoadedForLocalization) {
  const std::string map = joinPath(dir_, "walking.ysmap");
  std::string so, se;
  ASSERT_EQ(runTool({"--sequence", seq(), "--out", joinPath(dir_, "out_map_save"), "--boxes-from-gt", "--sequential",
                     "--save-map", map},
                    joinPath(dir_, "map_save"), so, se),
            0)
      << so << se;
  const Json saved = statsOf(joinPath(dir_, "out_map_save"))["map_file"]["saved"];
  ASSERT_TRUE(saved.is_object()) << saved.dump();
  EXPECT_EQ(numberOf(saved, "bytes"), static_cast<double>(fs::file_size(map))) << saved.dump();
  EXPECT_GT(numberOf(saved, "keyframes"), 0) << saved.dump();
  EXPECT_GE(numberOf(saved, "ms"), 0) << saved.dump();

  const std::string out = joinPath(dir_, "out_map_load");
  ASSERT_EQ(runTool({"--sequence", seq(), "--out", out, "--boxes-from-gt", "--sequential", "--load-map", map,
                     "--localization"},
                    joinPath(dir_, "map_load"), so, se),
            0)
      << so << se;
  const Json js = statsOf(out);
  const Json mf = js["map_file"];
  EXPECT_EQ(mf["localization"], true) << mf.dump();
  EXPECT_TRUE(mf["saved"].is_null()) << mf.dump();
  EXPECT_EQ(numberOf(mf["loaded"], "keyframes"), numberOf(saved, "keyframes")) << mf.dump();
  // Localization: relocalised in the loaded map, which got no keyframe.
  EXPECT_GE(numberOf(js, "relocalizations"), 1) << js.dump();
  EXPECT_EQ(numberOf(js, "keyframes"), numberOf(saved, "keyframes")) << js.dump();
  EXPECT_GT(numberOf(js, "trajectory_poses"), kFrames / 2) << js.dump();
}

TEST_F(RunnerMetrics, BadMapFilesAreOneLineErrors) {
  std::string so, se;
  const std::string missing = joinPath(dir_, "missing.ysmap");
  EXPECT_EQ(runTool({"--sequence", seq(), "--out", joinPath(dir_, "o"), "--load-map", missing},
                    joinPath(dir_, "map_missing"), so, se),
            1);
  EXPECT_EQ(se.rfind("error: " + missing + ": map file not found", 0), 0u) << se;
  EXPECT_EQ(se.find('\n'), se.size() - 1) << se;
  // A folder that does not exist fails before the run, not after it.
  EXPECT_EQ(runTool({"--sequence", seq(), "--out", joinPath(dir_, "o"), "--save-map", "/nonexistent/m.ysmap"},
                    joinPath(dir_, "map_nofolder"), so, se),
            1);
  EXPECT_EQ(se.rfind("error: /nonexistent/m.ysmap", 0), 0u) << se;
}
