#pragma once
// Helpers of the robustness tests: a small generated sequence (sim module), yolo_slam_run as a
// child process, and reading what it left in its output folder.
#include "yolo_slam/common/json.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/sim/generator.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
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

namespace yolo_slam {
namespace robustness {

namespace fs = std::filesystem;

// Frames of the generated sequence: enough for tracking to initialise and a signal to land
// mid-run at --realtime (30 fps: under a second of stamps).
constexpr int kFrames = 24;
// Generous bound for a run that must not hang (a few seconds of work on a loaded machine).
constexpr int kRunTimeoutS = 120;

inline std::string tool() { return joinPath(YOLO_SLAM_BIN_DIR, "yolo_slam_run"); }

inline std::string readAll(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Pose lines (not comments) of a TUM trajectory file; 0 when it does not exist.
inline size_t poseLines(const std::string& path) {
  std::ifstream f(path);
  size_t n = 0;
  for (std::string l; std::getline(f, l);)
    if (!l.empty() && l[0] != '#') ++n;
  return n;
}

inline Json statsOf(const std::string& out) {
  const std::string path = joinPath(out, "stats.json");
  return parseJson(readAll(path), path);
}

// A temporary folder holding a generated static_xyz sequence (seq/) and the tests' outputs.
class TempTree {
 public:
  explicit TempTree(const std::string& tag) {
    std::string tmpl = "/tmp/ys_" + tag + "_XXXXXX";
    const char* d = ::mkdtemp(tmpl.data());
    EXPECT_NE(d, nullptr) << "cannot create a temporary folder in /tmp";
    root_ = d ? d : "/tmp/ys_failed";
  }
  ~TempTree() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  TempTree(const TempTree&) = delete;
  TempTree& operator=(const TempTree&) = delete;
  std::string path(const std::string& name) const { return joinPath(root_, name); }

  // Writes the sequence to path(name); masks/ removed (screening metrics are not under test).
  std::string generate(const std::string& name, int frames = kFrames) const {
    sim::SynthOptions so;
    so.preset = "static_xyz";
    so.seed = 1;
    so.frames = frames;
    const std::string dir = path(name);
    sim::SequenceGenerator(so).generate(dir);
    std::error_code ec;
    fs::remove_all(joinPath(dir, "masks"), ec);
    return dir;
  }
  // A copy of the sequence `from` to mutate.
  std::string copy(const std::string& from, const std::string& name) const {
    const std::string dir = path(name);
    fs::copy(from, dir, fs::copy_options::recursive);
    return dir;
  }

 private:
  std::string root_;
};

// A copy `name` of the sequence `from` whose stamps (rgb and depth of a row of
// associations.txt, the list the runner reads) are `retime(row, stamp)`; groundtruth.txt is
// dropped (its stamps no longer match).
template <class Retime>
std::string withStamps(const TempTree& tree, const std::string& from, const std::string& name, Retime retime) {
  const std::string dir = tree.copy(from, name);
  const std::string list = joinPath(dir, "associations.txt");
  std::ifstream in(list);
  std::ostringstream out;
  int row = 0;
  for (std::string line; std::getline(in, line);) {
    std::istringstream ss(line);
    double rgb_t = 0, depth_t = 0;
    std::string rgb, depth;
    if (!(ss >> rgb_t >> rgb >> depth_t >> depth)) continue;
    char buf[512];
    std::snprintf(buf, sizeof buf, "%.6f %s %.6f %s\n", retime(row, rgb_t), rgb.c_str(), retime(row, depth_t),
                  depth.c_str());
    out << buf;
    ++row;
  }
  in.close();
  std::ofstream(list) << out.str();
  fs::remove(joinPath(dir, "groundtruth.txt"));
  return dir;
}

// A started yolo_slam_run with stdout and stderr in files. A child not waited for (a failed
// assertion returned early) is killed when this goes out of scope, never left running.
struct Child {
  pid_t pid = -1;
  bool reaped = false;
  std::string out_path, err_path;

  Child() = default;
  Child(Child&& o) noexcept : pid(o.pid), reaped(o.reaped), out_path(o.out_path), err_path(o.err_path) { o.pid = -1; }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() {
    if (pid <= 0 || reaped) return;
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
  }
  std::string err() const { return readAll(err_path); }
};

// The default: no vocabulary (faster), dynamic mode off.
inline std::vector<std::string> runArgs(const std::string& seq, const std::string& out,
                                        std::vector<std::string> extra = {}) {
  std::vector<std::string> a = {"--sequence", seq, "--out", out, "--no-vocabulary", "--dynamic-mode", "off"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

// `stdout_fd`/`stderr_fd` >= 0 replace the log files (a pipe, for the SIGPIPE test).
inline Child spawn(const std::vector<std::string>& args, const std::string& log_prefix, int stdout_fd = -1,
                   int stderr_fd = -1) {
  Child c;
  c.out_path = log_prefix + ".out";
  c.err_path = log_prefix + ".err";
  std::vector<std::string> all = {tool()};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  c.pid = ::fork();
  if (c.pid == 0) {
    const int o = stdout_fd >= 0 ? stdout_fd : ::open(c.out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = stderr_fd >= 0 ? stderr_fd : ::open(c.err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(o, 1);
    ::dup2(e, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return c;
}

// How a child ended: its exit code, or minus the signal that killed it.
constexpr int kTimedOut = -1000;
inline int waitExit(Child& c, int timeout_s = kRunTimeoutS) {
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  while (true) {
    const pid_t r = ::waitpid(c.pid, &status, WNOHANG);
    if (r == c.pid) break;
    if (r < 0) return kTimedOut;
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(timeout_s)) return kTimedOut;  // ~Child kills it
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  c.reaped = true;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

inline int runTool(const std::vector<std::string>& args, const std::string& log_prefix, std::string& err) {
  Child c = spawn(args, log_prefix);
  const int rc = waitExit(c);
  err = c.err();
  return rc;
}

// Polls until `ready()` or the timeout; false on timeout.
template <class Pred>
bool waitFor(Pred ready, int timeout_s = kRunTimeoutS) {
  const auto t0 = std::chrono::steady_clock::now();
  while (!ready()) {
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(timeout_s)) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

// A suite of runner tests over one sequence in its own temporary tree, made once per suite;
// every test skips when yolo_slam_run is not built. `Suite` names the tree (kTree) and makes
// the sequence in it (makeSequence), both public.
template <class Suite>
class RunSuite : public ::testing::Test {
 protected:
  static inline TempTree* tree_ = nullptr;
  static inline std::string seq_;
  static void SetUpTestSuite() {
    tree_ = new TempTree(Suite::kTree);
    seq_ = Suite::makeSequence(*tree_);
  }
  static void TearDownTestSuite() {
    delete tree_;
    tree_ = nullptr;
  }
  void SetUp() override {
    if (!fileExists(tool())) GTEST_SKIP() << tool() << " not built (make yolo_slam_run)";
  }
};

}  // namespace robustness
}  // namespace yolo_slam
