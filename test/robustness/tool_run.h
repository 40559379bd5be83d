#pragma once
// Helpers of the bad-input tests: a small generated sequence per test suite, and the tools run as
// child processes with their exit status (a signal is a crash) and a hang guard.
#include "yolo_slam/common/paths.h"
#include "yolo_slam/sim/generator.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace robustness {

inline std::string toolPath(const std::string& name) { return yolo_slam::joinPath(YOLO_SLAM_BIN_DIR, name); }

inline std::string readAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

inline void writeAll(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

// Non-comment lines of a text file (poses of a trajectory).
inline size_t dataLines(const std::string& path) {
  std::ifstream f(path);
  size_t n = 0;
  for (std::string l; std::getline(f, l);)
    if (!l.empty() && l[0] != '#') ++n;
  return n;
}

// How a child ended: its exit code, or the signal that killed it, or a hang (killed by us).
struct Outcome {
  int exit_code = -1;  // -1 unless it exited
  int signal = 0;      // the signal that ended it (0 if it exited)
  bool hung = false;   // still running after the time limit: killed
  std::string out, err;
  bool exited() const { return exit_code >= 0 && !hung; }
};

inline std::ostream& operator<<(std::ostream& os, const Outcome& o) {
  return os << "exit " << o.exit_code << ", signal " << o.signal << (o.hung ? ", hung" : "") << "\nstdout:\n"
            << o.out << "\nstderr:\n" << o.err;
}

// Runs tool `name` with `args`; killed (Outcome::hung) when still running after `limit`. A generous
// limit: it guards against a hang, it does not time anything.
inline Outcome runTool(const std::string& name, const std::vector<std::string>& args, const std::string& log_prefix,
                       std::chrono::seconds limit = std::chrono::seconds(120)) {
  const std::string out_path = log_prefix + ".out", err_path = log_prefix + ".err";
  std::vector<std::string> all = {toolPath(name)};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int o = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(o, 1);
    ::dup2(e, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  Outcome r;
  const auto deadline = std::chrono::steady_clock::now() + limit;
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      r.hung = true;
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!r.hung && WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  if (!r.hung && WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  r.out = readAll(out_path);
  r.err = readAll(err_path);
  return r;
}

inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A temp root holding one generated sequence (dir/seq_template), copied per test so that each
// corrupts its own.
class SequenceSuite : public ::testing::Test {
 protected:
  static constexpr int kFrames = 12;
  static inline std::string root_;

  static void SetUpTestSuite() {
    char tmpl[] = "/tmp/ys_bad_input_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    root_ = tmpl;
    yolo_slam::sim::SynthOptions so;
    so.preset = "static_xyz";
    so.seed = 2;
    so.frames = kFrames;
    yolo_slam::sim::SequenceGenerator(so).generate(yolo_slam::joinPath(root_, "seq_template"));
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    if (!root_.empty()) std::filesystem::remove_all(root_, ec);
  }
  void SetUp() override {
    if (!yolo_slam::fileExists(toolPath("yolo_slam_run"))) GTEST_SKIP() << "yolo_slam_run not built";
  }

  // A fresh copy of the generated sequence, named after the running test.
  static std::string freshSequence() {
    static int copies = 0;
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    const std::string dir = yolo_slam::joinPath(root_, name + "_" + std::to_string(++copies));
    std::filesystem::copy(yolo_slam::joinPath(root_, "seq_template"), dir, std::filesystem::copy_options::recursive);
    return dir;
  }
  static std::string path(const std::string& name) { return yolo_slam::joinPath(root_, name); }

  // yolo_slam_run on `seq` with tracking only (no detector, no vocabulary: fast), plus `extra`.
  static Outcome runSlam(const std::string& seq, const std::vector<std::string>& extra = {}) {
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::vector<std::string> args = {"--sequence", seq, "--out", path(name + "_out"), "--no-vocabulary",
                                     "--set", "Screening.mode=off"};
    args.insert(args.end(), extra.begin(), extra.end());
    return runTool("yolo_slam_run", args, path(name));
  }
  static std::string outDir() {
    return path(std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_out");
  }
};
}  // namespace robustness
