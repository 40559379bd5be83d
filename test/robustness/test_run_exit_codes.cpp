// yolo_slam_run exit codes and pacing (issue 22, defects 3 and 4): a run that tracked (almost)
// nothing exits 3 with a summary of why while still writing everything; --realtime and
// --camera-rate play a long forward stamp gap as a short one, with a warning.
#include "run_tool.h"

#include <opencv2/imgcodecs.hpp>

using namespace yolo_slam;
using namespace yolo_slam::robustness;

namespace {

constexpr int kExitTooFewTracked = 3;
// Frame after which the gap sequence's stamps jump forward.
constexpr int kGapFrame = 10;
constexpr double kGapS = 1000.0;

class RunExitCodes : public RunSuite<RunExitCodes> {
 public:
  static constexpr const char* kTree = "run_exit_codes";
  static std::string makeSequence(TempTree& tree) {
    return tree.generate("seq");
  }

 protected:

  // Every image of `sub` (rgb or depth) in a copy of the sequence replaced by `make()`.
  template <class Make>
  static std::string withImages(const std::string& name, const std::string& sub, Make make) {
    const std::string dir = tree_->copy(seq_, name);
    for (const auto& e : fs::directory_iterator(joinPath(dir, sub)))
      EXPECT_TRUE(cv::imwrite(e.path().string(), make()));
    return dir;
  }

  // A run that must exit 3 naming `why` in its summary, with every output written.
  static void expectTooFewTracked(const std::string& seq, const std::string& why, const std::string& log) {
    const std::string out = tree_->path("out_" + log);
    std::string err;
    EXPECT_EQ(runTool(runArgs(seq, out), tree_->path(log), err), kExitTooFewTracked) << err;
    EXPECT_NE(err.find("error: tracked 0 of " + std::to_string(kFrames) + " frames"), std::string::npos) << err;
    EXPECT_NE(err.find(why), std::string::npos) << err;
    EXPECT_TRUE(fileExists(joinPath(out, "CameraTrajectory.txt"))) << err;
    EXPECT_TRUE(fileExists(joinPath(out, "KeyFrameTrajectory.txt"))) << err;
    const Json js = statsOf(out);
    EXPECT_EQ(js["complete"], false) << js.dump();
    EXPECT_EQ(js["status"], "too few frames tracked") << js.dump();
    EXPECT_EQ(js["tracked"], 0) << js.dump();
  }
};

// The sequence with every stamp from frame kGapFrame on moved kGapS later.
std::string withStampGap(const TempTree& tree, const std::string& seq) {
  return withStamps(tree, seq, "gap", [](int row, double t) { return row >= kGapFrame ? t + kGapS : t; });
}

}  // namespace

TEST_F(RunExitCodes, AGoodRunExitsZero) {
  std::string err;
  EXPECT_EQ(runTool(runArgs(seq_, tree_->path("out_good"), {"--min-tracked", "0.9"}), tree_->path("good"), err), 0)
      << err;
}

TEST_F(RunExitCodes, AllImagesMissingExitsThree) {
  const std::string dir = tree_->copy(seq_, "no_rgb");
  fs::remove_all(joinPath(dir, "rgb"));
  expectTooFewTracked(dir, std::to_string(kFrames) + " without an image", "no_rgb");
}

TEST_F(RunExitCodes, AllZeroDepthExitsThreeWithAWarning) {
  const std::string dir = withImages("zero_depth", "depth", [] { return cv::Mat(480, 640, CV_16U, cv::Scalar(0)); });
  expectTooFewTracked(dir, std::to_string(kFrames) + " without usable depth", "zero_depth");
  EXPECT_NE(readAll(tree_->path("zero_depth.err")).find("warning: frame 0"), std::string::npos);
}

TEST_F(RunExitCodes, AllBlackImagesExitThreeWithAWarning) {
  const std::string dir = withImages("black", "rgb", [] { return cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0)); });
  expectTooFewTracked(dir, std::to_string(kFrames) + " without keypoints", "black");
  EXPECT_NE(readAll(tree_->path("black.err")).find("no keypoint found"), std::string::npos);
}

TEST_F(RunExitCodes, WrongSizeDepthExitsThree) {
  const std::string dir =
      withImages("small_depth", "depth", [] { return cv::Mat(240, 320, CV_16U, cv::Scalar(5000)); });
  expectTooFewTracked(dir, std::to_string(kFrames) + " without usable depth", "small_depth");
}

TEST_F(RunExitCodes, MinTrackedZeroAcceptsAnyRunAndBadValuesAreRefused) {
  const std::string dir = tree_->path("black");  // from AllBlackImagesExitThreeWithAWarning, or made here
  const std::string seq =
      dirExists(dir) ? dir : withImages("black", "rgb", [] { return cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0)); });
  std::string err;
  EXPECT_EQ(runTool(runArgs(seq, tree_->path("out_black0"), {"--min-tracked", "0"}), tree_->path("black0"), err), 0)
      << err;
  for (const char* bad : {"-0.1", "1.5", "nan", "half"}) {
    EXPECT_EQ(runTool(runArgs(seq_, tree_->path("out_bad"), {"--min-tracked", bad}), tree_->path("bad"), err), 1)
        << bad;
    EXPECT_EQ(err.rfind("error: --min-tracked must be a fraction in [0, 1]", 0), 0u) << err;
  }
}

TEST_F(RunExitCodes, LongStampGapIsCappedAndWarnedAbout) {
  const std::string gap = withStampGap(*tree_, seq_);
  for (const char* flag : {"--realtime", "--camera-rate"}) {
    const std::string out = tree_->path(std::string("out_gap") + flag);
    std::string err;
    // Without the cap the run would sleep kGapS; the bound is far below that, far above the work.
    Child c = spawn(runArgs(gap, out, {flag, "--min-tracked", "0"}), tree_->path("gap"));
    const int rc = waitExit(c, kRunTimeoutS);
    err = c.err();
    EXPECT_EQ(rc, 0) << flag << "\n" << err;
    EXPECT_NE(err.find("warning: stamps jump forward 1000."), std::string::npos) << err;
    EXPECT_NE(err.find(std::string(flag) + " plays a gap over 2 s as 2 s"), std::string::npos) << err;
    EXPECT_EQ(statsOf(out)["complete"], true) << flag;
  }
}

TEST_F(RunExitCodes, CtrlCDuringAStampGapStopsTheRunPromptly) {
  const std::string gap = tree_->path("gap");
  const std::string seq = dirExists(gap) ? gap : withStampGap(*tree_, seq_);
  for (const char* flag : {"--realtime", "--camera-rate"}) {
    const std::string out = tree_->path(std::string("out_gap_int") + flag);
    Child c = spawn(runArgs(seq, out, {flag}), tree_->path("gap_int"));
    // The frames before the gap are tracked; the run now waits in the gap.
    ASSERT_TRUE(waitFor([&] { return poseLines(joinPath(out, "CameraTrajectory.partial.txt")) >= kGapFrame - 1; }))
        << c.err();
    ::kill(c.pid, SIGINT);
    EXPECT_EQ(waitExit(c, kRunTimeoutS), 130) << flag << "\n" << c.err();
    const Json js = statsOf(out);
    EXPECT_EQ(js["status"], "interrupted") << js.dump();
    EXPECT_GE(poseLines(joinPath(out, "CameraTrajectory.txt")), static_cast<size_t>(kGapFrame - 1)) << flag;
  }
}
