// yolo_slam_run output safety (issue 22, defect 1 and the consistent output set of defect 2):
// every output is checked before the first frame (an unwritable --out, a folder in place of an
// output file, an unwritable --save-map fail at once, naming the path); a finished run leaves
// exactly its own files with stats.json saying "complete"; a run replaces the previous run's
// files in the folder when it starts.
#include "run_tool.h"

using namespace yolo_slam;
using namespace yolo_slam::robustness;

namespace {

class RunOutputs : public RunSuite<RunOutputs> {
 public:
  static constexpr const char* kTree = "run_outputs";
  static std::string makeSequence(TempTree& tree) {
    return tree.generate("seq");
  }

 protected:
  // Runs and expects a refusal before the first frame: exit 1, one error line naming `path`.
  static void expectRefusedBeforeWork(const std::vector<std::string>& args, const std::string& path,
                                      const std::string& log) {
    std::string err;
    EXPECT_EQ(runTool(args, tree_->path(log), err), 1) << err;
    EXPECT_EQ(err.rfind("error: " + path + ":", 0), 0u) << err;
    // The header line comes right before the first frame: no frame was processed.
    EXPECT_EQ(err.find("yolo_slam_run: "), std::string::npos) << err;
  }
};

std::vector<std::string> filesIn(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST_F(RunOutputs, UnwritableOutFolderFailsBeforeAnyFrame) {
  expectRefusedBeforeWork(runArgs(seq_, "/proc"), "/proc", "proc");
}

TEST_F(RunOutputs, OutNamingAFileFailsBeforeAnyFrame) {
  const std::string file = tree_->path("a_file");
  std::ofstream(file) << "x";
  expectRefusedBeforeWork(runArgs(seq_, file), file, "file_out");
}

TEST_F(RunOutputs, FolderInPlaceOfAnOutputFileFailsBeforeAnyFrame) {
  for (const char* name : {"CameraTrajectory.txt", "KeyFrameTrajectory.txt.tmp", "boxes_screened.txt", "stats.json",
                           "CameraTrajectory.partial.txt"}) {
    const std::string out = tree_->path(std::string("blocked_") + name);
    fs::create_directories(joinPath(out, name));
    expectRefusedBeforeWork(runArgs(seq_, out), joinPath(out, name), std::string("blocked_") + name);
    EXPECT_TRUE(dirExists(joinPath(out, name))) << "the folder in the way is left alone";
  }
}

TEST_F(RunOutputs, UnwritableSaveMapFailsBeforeAnyFrame) {
  const std::string out = tree_->path("out_map");
  expectRefusedBeforeWork(runArgs(seq_, out, {"--save-map", "/proc/x.ysmap"}), "/proc/x.ysmap", "map_proc");
  const std::string folder = tree_->path("map_is_a_folder");
  fs::create_directories(folder);
  expectRefusedBeforeWork(runArgs(seq_, out, {"--save-map", folder}), folder, "map_folder");
  const std::string missing = tree_->path("no_such_folder/x.ysmap");
  expectRefusedBeforeWork(runArgs(seq_, out, {"--save-map", missing}), missing, "map_missing");
}

TEST_F(RunOutputs, AFinishedRunLeavesExactlyItsFilesAndSaysComplete) {
  const std::string out = tree_->path("out_complete");
  // A previous run's leftovers, of another mode: none may survive into this run's folder.
  fs::create_directories(out);
  for (const char* stale : {"boxes_screened.txt", "CameraTrajectory.txt.tmp", "CameraTrajectory.partial.txt"})
    std::ofstream(joinPath(out, stale)) << "# from an earlier run\n";
  std::string err;
  ASSERT_EQ(runTool(runArgs(seq_, out), tree_->path("complete"), err), 0) << err;
  EXPECT_EQ(filesIn(out), (std::vector<std::string>{"CameraTrajectory.txt", "KeyFrameTrajectory.txt", "frames.txt",
                                                    "stats.json"}));
  const Json js = statsOf(out);
  EXPECT_EQ(js["files"]["frames"], "frames.txt") << js.dump();
  EXPECT_EQ(js["complete"], true) << js.dump();
  EXPECT_EQ(js["status"], "finished") << js.dump();
  EXPECT_EQ(js["files"]["camera_trajectory"], "CameraTrajectory.txt") << js.dump();
  EXPECT_TRUE(js["files"]["boxes_screened"].is_null()) << js.dump();
  EXPECT_EQ(js["tracking"]["frames_read"], kFrames) << js.dump();
  EXPECT_EQ(js["trajectory_poses"], poseLines(joinPath(out, "CameraTrajectory.txt"))) << js.dump();
}

TEST_F(RunOutputs, ScreenedBoxesAreRenamedIntoPlaceAtTheEnd) {
  const std::string out = tree_->path("out_boxes");
  std::string err;
  ASSERT_EQ(
      runTool({"--sequence", seq_, "--out", out, "--no-vocabulary", "--dynamic-mode", "detect", "--boxes-from-gt"},
              tree_->path("boxes"), err),
      0)
      << err;
  EXPECT_EQ(filesIn(out), (std::vector<std::string>{"CameraTrajectory.txt", "KeyFrameTrajectory.txt",
                                                    "boxes_screened.txt", "frames.txt", "stats.json"}));
  EXPECT_EQ(readAll(joinPath(out, "boxes_screened.txt")).rfind("# rgb_stamp index label", 0), 0u);
  EXPECT_EQ(statsOf(out)["files"]["boxes_screened"], "boxes_screened.txt");
}

