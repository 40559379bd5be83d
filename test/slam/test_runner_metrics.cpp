// yolo_slam_run on a short synthetic walking_xyz sequence (sim library, written to a temp
// folder): screening metrics against the masks in stats.json, corrupt/missing masks, default
// and explicit vocabulary/config handling, and Ctrl-C (SIGINT to the running child) still
// writing the trajectory so far and a valid stats.json.
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

// The JSON object (braces included) that follows "key": in text; "" if absent.
std::string jsonObject(const std::string& text, const std::string& key) {
  const auto k = text.find("\"" + key + "\":");
  if (k == std::string::npos) return "";
  const auto b = text.find_first_not_of(" ", k + key.size() + 3);
  if (b == std::string::npos || text[b] != '{') return text.substr(b, text.find_first_of(",\n", b) - b);
  int depth = 0;
  for (size_t i = b; i < text.size(); ++i) {
    depth += text[i] == '{' ? 1 : text[i] == '}' ? -1 : 0;
    if (depth == 0) return text.substr(b, i - b + 1);
  }
  return "";
}

// The number after "key": in text; NaN if absent or not a number.
double jsonNumberOf(const std::string& text, const std::string& key) {
  const auto k = text.find("\"" + key + "\":");
  if (k == std::string::npos) return NAN;
  const char* s = text.c_str() + k + key.size() + 3;
  char* end = nullptr;
  const double v = std::strtod(s, &end);
  return end == s ? NAN : v;
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
  const std::string js = readAll(joinPath(out, "stats.json"));
  const std::string m = jsonObject(js, "screening_metrics");
  ASSERT_FALSE(m.empty()) << js;
  ASSERT_EQ(m[0], '{') << js;
  EXPECT_EQ(jsonNumberOf(m, "frames"), kFrames) << m;
  const double dyn = jsonNumberOf(m, "dynamic_keypoints"), dropped = jsonNumberOf(m, "dropped");
  EXPECT_GT(dyn, 100) << m;  // people fill a good part of walking_xyz frames
  EXPECT_LE(dropped, dyn) << m;
  const double recall = jsonNumberOf(m, "dynamic_recall");
  EXPECT_NEAR(recall, dropped / dyn, 1e-3) << m;
  EXPECT_GT(recall, 0.5) << m;
  const double sib = jsonNumberOf(m, "static_in_boxes"), kept = jsonNumberOf(m, "kept");
  EXPECT_GT(sib, 0) << m;
  EXPECT_LE(kept, sib) << m;
  const double retention = jsonNumberOf(m, "static_retention");
  EXPECT_NEAR(retention, kept / sib, 1e-3) << m;
  EXPECT_GE(retention, 0.0);
  EXPECT_LE(retention, 1.0);
  // Detection/screening time and keypoint counts of the screening itself.
  const std::string kp = jsonObject(js, "keypoints");
  EXPECT_GT(jsonNumberOf(kp, "in_boxes"), 0) << kp;
  EXPECT_EQ(jsonNumberOf(kp, "in_boxes"), jsonNumberOf(kp, "kept") + jsonNumberOf(kp, "dropped")) << kp;
  const std::string timings = jsonObject(js, "timings");
  EXPECT_FALSE(jsonObject(timings, "screening").empty()) << js;
  EXPECT_FALSE(jsonObject(timings, "detection").empty()) << js;
  EXPECT_EQ(lineCount(joinPath(out, "CameraTrajectory.txt")), jsonNumberOf(js, "trajectory_poses"));
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
  const std::string js = readAll(joinPath(second, "stats.json"));
  EXPECT_EQ(jsonNumberOf(jsonObject(js, "boxes_screened"), "detected"), static_cast<double>(want.size())) << js;

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
                     "--max-frames", "10"},
                    joinPath(dir_, "off"), so, se),
            0)
      << so << se;
  EXPECT_NE(se.find("vocabulary: none"), std::string::npos) << se;
  const std::string m = jsonObject(readAll(joinPath(out, "stats.json")), "screening_metrics");
  EXPECT_EQ(jsonNumberOf(m, "frames"), 10) << m;
  EXPECT_GT(jsonNumberOf(m, "dynamic_keypoints"), 0) << m;
  EXPECT_EQ(jsonNumberOf(m, "dropped"), 0) << m;
  EXPECT_EQ(jsonNumberOf(m, "dynamic_recall"), 0) << m;
  EXPECT_EQ(jsonNumberOf(m, "static_dropped"), 0) << m;
  // No box in mode off: retention has no denominator.
  EXPECT_EQ(jsonNumberOf(m, "static_in_boxes"), 0) << m;
  EXPECT_NE(m.find("\"static_retention\": null"), std::string::npos) << m;
  EXPECT_NE(readAll(joinPath(out, "stats.json")).find("\"sequential\": false"), std::string::npos);
}

TEST_F(RunnerMetrics, SequentialRunsWriteIdenticalTrajectories) {
  std::string traj[2];
  for (int k = 0; k < 2; ++k) {
    const std::string out = joinPath(dir_, "out_sequential" + std::to_string(k));
    std::string so, se;
    ASSERT_EQ(runTool({"--sequence", seq(), "--out", out, "--boxes-from-gt", "--sequential"},
                      joinPath(dir_, "sequential" + std::to_string(k)), so, se),
              0)
        << so << se;
    EXPECT_NE(readAll(joinPath(out, "stats.json")).find("\"sequential\": true"), std::string::npos);
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
  const std::string m = jsonObject(readAll(joinPath(out, "stats.json")), "screening_metrics");
  EXPECT_EQ(jsonNumberOf(m, "frames"), 4) << m;
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
  Child c = spawn({"--sequence", seq(), "--out", out, "--boxes-from-gt", "--no-vocabulary", "--realtime"},
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
  const std::string js = readAll(joinPath(out, "stats.json"));
  ASSERT_FALSE(js.empty());
  EXPECT_EQ(js.back(), '\n');
  EXPECT_NE(js.find("\"interrupted\": true"), std::string::npos) << js;
  EXPECT_EQ(jsonNumberOf(js, "trajectory_poses"), poses) << js;
  const double frames = jsonNumberOf(jsonObject(js, "screening_metrics"), "frames");
  EXPECT_GE(frames, 1) << js;
  EXPECT_LT(frames, kFrames) << js;
}
