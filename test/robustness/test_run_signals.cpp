// yolo_slam_run under signals (issue 22, defect 2): the tracking poses are on disk while the
// run goes on (SIGKILL keeps them, stats.json says the run did not finish), SIGHUP and SIGTERM
// write the results like SIGINT (exit 128 + signal), a second Ctrl-C right after the first
// does not abort the final write while a third quits at once, and a closed output pipe
// (SIGPIPE) does not end the run.
#include "yolo_slam/io/trajectory.h"

#include "run_tool.h"

using namespace yolo_slam;
using namespace yolo_slam::robustness;

namespace {

// Poses on disk before a signal is sent: the run is past initialisation, mid-sequence.
constexpr size_t kPosesBeforeSignal = 3;
// The sequence played this many times slower than recorded: a few seconds at --realtime, so a
// signal sent after the first poses lands mid-run even on a loaded machine.
constexpr double kSlowDown = 4.0;
// Between two signals (the reproduction: a second Ctrl-C 50 ms after the first).
constexpr auto kSecondSignalDelay = std::chrono::milliseconds(50);

class RunSignals : public RunSuite<RunSignals> {
 public:
  static constexpr const char* kTree = "run_signals";
  static std::string makeSequence(TempTree& tree) {
    const std::string recorded = tree.generate("recorded");
    std::ifstream first(joinPath(recorded, "associations.txt"));
    double t0 = 0;
    first >> t0;
    return withStamps(tree, recorded, "seq", [t0](int, double t) { return t0 + (t - t0) * kSlowDown; });
  }

 protected:
  static std::string partialOf(const std::string& out) { return joinPath(out, "CameraTrajectory.partial.txt"); }

  // Starts a --realtime run (a few seconds of stamps) and waits until poses are on disk.
  static Child startMidRun(const std::string& out, const std::string& log) {
    Child c = spawn(runArgs(seq_, out, {"--realtime"}), tree_->path(log));
    EXPECT_GT(c.pid, 0);
    EXPECT_TRUE(waitFor([&] { return poseLines(partialOf(out)) >= kPosesBeforeSignal; })) << c.err();
    return c;
  }

  // The results of a run stopped by `sig`: exit 128 + sig, every output written, the partial
  // trajectory gone, stats.json complete false with the reason.
  static void expectInterruptedResults(const Child& c, int rc, const std::string& out, const std::string& signal_name,
                                       int sig) {
    const std::string err = c.err();
    EXPECT_EQ(rc, 128 + sig) << err;
    EXPECT_NE(err.find("interrupted by " + signal_name), std::string::npos) << err;
    const std::string traj = joinPath(out, "CameraTrajectory.txt");
    EXPECT_GE(poseLines(traj), kPosesBeforeSignal) << err;
    EXPECT_LT(poseLines(traj), static_cast<size_t>(kFrames)) << err;
    EXPECT_TRUE(fileExists(joinPath(out, "KeyFrameTrajectory.txt"))) << err;
    EXPECT_FALSE(fileExists(partialOf(out))) << err;
    const Json js = statsOf(out);
    EXPECT_EQ(js["complete"], false) << js.dump();
    EXPECT_EQ(js["status"], "interrupted") << js.dump();
    EXPECT_EQ(js["signal"], signal_name) << js.dump();
    EXPECT_EQ(js["trajectory_poses"], poseLines(traj)) << js.dump();
  }
};

}  // namespace

TEST_F(RunSignals, SigkillKeepsThePosesEstimatedSoFar) {
  const std::string out = tree_->path("out_kill");
  // A previous run's final trajectory must not pass for this run's.
  fs::create_directories(out);
  std::ofstream(joinPath(out, "CameraTrajectory.txt")) << "# from an earlier run\n";
  Child c = startMidRun(out, "kill");
  ::kill(c.pid, SIGKILL);
  EXPECT_EQ(waitExit(c), -SIGKILL);
  const Trajectory poses = io::readTrajectory(partialOf(out));  // throws on a torn line
  EXPECT_GE(poses.size(), kPosesBeforeSignal);
  for (size_t k = 1; k < poses.size(); ++k) EXPECT_LT(poses[k - 1].stamp, poses[k].stamp);
  EXPECT_FALSE(fileExists(joinPath(out, "CameraTrajectory.txt")));
  const Json js = statsOf(out);
  EXPECT_EQ(js["complete"], false) << js.dump();
  EXPECT_EQ(js["status"], "running") << js.dump();
  EXPECT_EQ(js["files"]["partial_trajectory"], "CameraTrajectory.partial.txt") << js.dump();
}

TEST_F(RunSignals, SighupWritesTheResults) {
  const std::string out = tree_->path("out_hup");
  Child c = startMidRun(out, "hup");
  ::kill(c.pid, SIGHUP);
  expectInterruptedResults(c, waitExit(c), out, "SIGHUP", SIGHUP);
}

TEST_F(RunSignals, SigtermWritesTheResults) {
  const std::string out = tree_->path("out_term");
  Child c = startMidRun(out, "term");
  ::kill(c.pid, SIGTERM);
  expectInterruptedResults(c, waitExit(c), out, "SIGTERM", SIGTERM);
}

TEST_F(RunSignals, ASecondCtrlCDoesNotAbortTheFinalWrite) {
  const std::string out = tree_->path("out_int2");
  Child c = startMidRun(out, "int2");
  ::kill(c.pid, SIGINT);
  std::this_thread::sleep_for(kSecondSignalDelay);
  ::kill(c.pid, SIGINT);
  expectInterruptedResults(c, waitExit(c), out, "SIGINT", SIGINT);
}

TEST_F(RunSignals, AThirdSignalQuitsAtOnceKeepingThePartialTrajectory) {
  const std::string out = tree_->path("out_three");
  Child c = startMidRun(out, "three");
  // Three different signals while the child is stopped are all pending when it continues, so
  // they arrive before it can write anything (one signal of a kind would be merged).
  ::kill(c.pid, SIGSTOP);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) ::kill(c.pid, sig);
  ::kill(c.pid, SIGCONT);
  const int rc = waitExit(c);
  EXPECT_TRUE(rc == 128 + SIGINT || rc == 128 + SIGTERM || rc == 128 + SIGHUP) << rc << "\n" << c.err();
  EXPECT_NE(c.err().find("quitting at once"), std::string::npos) << c.err();
  EXPECT_GE(poseLines(partialOf(out)), kPosesBeforeSignal);
  EXPECT_FALSE(fileExists(joinPath(out, "CameraTrajectory.txt")));
  EXPECT_EQ(statsOf(out)["status"], "running");
}

TEST_F(RunSignals, AClosedOutputPipeDoesNotEndTheRun) {
  // `yolo_slam_run ... 2>&1 | head -2` once head has exited: every write fails with EPIPE.
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  ::close(fds[0]);
  const std::string out = tree_->path("out_pipe");
  Child c = spawn(runArgs(seq_, out), tree_->path("pipe"), fds[1], fds[1]);
  ::close(fds[1]);
  EXPECT_EQ(waitExit(c), 0);
  const Json js = statsOf(out);
  EXPECT_EQ(js["complete"], true) << js.dump();
  EXPECT_EQ(poseLines(joinPath(out, "CameraTrajectory.txt")), static_cast<size_t>(kFrames));
}
