// yolo_slam_eval and yolo_slam_detect with bad input: an estimate with coordinates around 1e160
// (was "rmse inf" with exit 0, and a hang in cv::line with --plot), an out-of-range thread count
// (was a crash at exit). Each ends with exit code 1, never a signal or a hang, and a message
// naming the file.
#include "robustness/tool_run.h"

#include <cstdint>
#include <cstdio>

using namespace robustness;
using yolo_slam::joinPath;

namespace {

class BadToolInput : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/ys_bad_tools_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return joinPath(dir_, name); }

  // A TUM trajectory of `n` poses on a line; pose `huge_at` (if < n) at x = 1e160.
  std::string trajectory(const std::string& name, size_t n, size_t huge_at = SIZE_MAX) const {
    std::string text = "# timestamp tx ty tz qx qy qz qw\n";
    for (size_t i = 0; i < n; ++i) {
      char line[160];
      std::snprintf(line, sizeof line, "%.6f %s 0.5 1.0 0 0 0 1\n", 100.0 + 0.1 * i,
                    i == huge_at ? "1e160" : std::to_string(0.01 * i).c_str());
      text += line;
    }
    writeAll(path(name), text);
    return path(name);
  }

  std::string dir_;
};

}  // namespace

TEST_F(BadToolInput, EvalRefusesHugeCoordinatesWithAndWithoutPlot) {
  if (!yolo_slam::fileExists(toolPath("yolo_slam_eval"))) GTEST_SKIP() << "yolo_slam_eval not built";
  const std::string gt = trajectory("gt.txt", 50);
  const std::string est = trajectory("est.txt", 50, 20);
  for (const bool plot : {false, true}) {
    std::vector<std::string> args = {"ate", gt, est};
    if (plot) args.insert(args.end(), {"--plot", path("ate.png")});
    const Outcome r = runTool("yolo_slam_eval", args, path(plot ? "plot" : "noplot"));
    ASSERT_FALSE(r.hung) << "yolo_slam_eval hung" << r;
    ASSERT_TRUE(r.exited()) << r;
    EXPECT_EQ(r.exit_code, 1) << r;
    EXPECT_TRUE(contains(r.err, est + " vs " + gt + ": ATE: the estimated pose at stamp 102.000000")) << r;
    EXPECT_TRUE(contains(r.err, "beyond 1e+09 m")) << r;
    EXPECT_FALSE(contains(r.out, "rmse")) << r;
    EXPECT_FALSE(yolo_slam::fileExists(path("ate.png"))) << r;
  }
  // A sound pair still evaluates.
  const Outcome ok = runTool("yolo_slam_eval", {"ate", gt, gt, "--plot", path("ok.png")}, path("ok"));
  EXPECT_EQ(ok.exit_code, 0) << ok;
  EXPECT_TRUE(yolo_slam::fileExists(path("ok.png"))) << ok;
}

TEST_F(BadToolInput, DetectBoundsTheThreadCount) {
  if (!yolo_slam::fileExists(toolPath("yolo_slam_detect"))) GTEST_SKIP() << "yolo_slam_detect not built";
  const std::string image = joinPath(yolo_slam::sharedDir(), "data/images/person.jpg");
  const Outcome r = runTool("yolo_slam_detect", {"--threads", "70000", image}, path("threads"));
  ASSERT_TRUE(r.exited()) << r;
  EXPECT_EQ(r.exit_code, 1) << r;
  EXPECT_TRUE(contains(r.err, "--threads must be in [1, 64]")) << r;
}
