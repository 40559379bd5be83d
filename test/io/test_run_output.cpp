// The run folder: outputs checked before a run starts, and files written as the run goes on.
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/io/atomic_file.h"
#include "yolo_slam/io/run_output.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace yolo_slam;
namespace fs = std::filesystem;

namespace {

class RunOutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/ys_run_output_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return joinPath(dir_, name); }
  std::string dir_;
};

std::string readAll(const std::string& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// The message of the Error `f` throws; empty when it throws none.
template <class F>
std::string errorOf(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_F(RunOutputTest, FolderIsCreatedAndProbedWithoutLeavingAFile) {
  const std::string out = path("a/b/out");
  io::prepareOutputFolder(out, io::RunFiles::all(), "--out");
  EXPECT_TRUE(dirExists(out));
  EXPECT_TRUE(fs::is_empty(out));
}

TEST_F(RunOutputTest, UnwritableOrBlockedOutputsAreRefusedNamingThePath) {
  EXPECT_EQ(errorOf([] {
              io::prepareOutputFolder("/proc", {"x.txt"}, "--out");
            }).rfind("/proc: the output folder is not writable", 0),
            0u);
  std::ofstream(path("file")) << "x";
  EXPECT_NE(errorOf([&] { io::prepareOutputFolder(path("file"), {}, "--out"); }).find("--out names a file"),
            std::string::npos);
  EXPECT_NE(
      errorOf([&] { io::prepareOutputFolder(path("file/sub"), {}, "--out"); }).find("cannot create the output folder"),
      std::string::npos);
  fs::create_directories(path("out/stats.json.tmp"));
  const std::string msg = errorOf([&] { io::prepareOutputFolder(path("out"), {"stats.json"}, "--out"); });
  EXPECT_EQ(msg.rfind(path("out/stats.json.tmp") + ": a folder has the name of an output file", 0), 0u) << msg;
  EXPECT_EQ(errorOf([] {
              io::checkOutputFile("/proc/m.ysmap", "--save-map");
            }).rfind("/proc/m.ysmap: --save-map folder /proc is not writable", 0),
            0u);
  EXPECT_NE(errorOf([&] { io::checkOutputFile(path("none/m.ysmap"), "--save-map"); }).find("does not exist"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { io::checkOutputFile(path("out"), "--save-map"); }).find("a folder has the name"),
            std::string::npos);
  EXPECT_EQ(errorOf([&] { io::checkOutputFile(path("m.ysmap"), "--save-map"); }), "");
}

TEST_F(RunOutputTest, IncrementalFileHoldsEveryAppendedLineBeforeItIsClosed) {
  io::IncrementalFile f(path("x.partial"), "# header\n");
  f.append("1\n");
  f.append("2\n");
  EXPECT_EQ(readAll(path("x.partial")), "# header\n1\n2\n");  // flushed, still open
  EXPECT_TRUE(f.finishAs(path("x.txt")));
  EXPECT_FALSE(fileExists(path("x.partial")));
  EXPECT_EQ(readAll(path("x.txt")), "# header\n1\n2\n");
}

TEST_F(RunOutputTest, IncrementalFileRemoveAndOpenFailure) {
  {
    io::IncrementalFile f(path("y.partial"), "");
    f.remove();
  }
  EXPECT_FALSE(fileExists(path("y.partial")));
  fs::create_directories(path("blocked"));
  EXPECT_NE(errorOf([&] { io::IncrementalFile g(path("blocked"), ""); }).find(path("blocked") + ": cannot create"),
            std::string::npos);
}

TEST_F(RunOutputTest, APreviousRunsFilesAreRemovedButStatsAndOtherFilesKept) {
  for (const std::string& name : io::RunFiles::all()) {
    std::ofstream(path(name)) << "old";
    std::ofstream(io::temporaryPathOf(path(name))) << "old";
  }
  std::ofstream(path("notes.txt")) << "mine";
  io::removePreviousRun(dir_);
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir_)) left.push_back(e.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"notes.txt", "stats.json"}));
}

TEST_F(RunOutputTest, AtomicWriteNamesTheTemporaryInTheWay) {
  fs::create_directories(path("s.json.tmp"));
  const std::string msg = errorOf([&] { io::writeFileAtomic(path("s.json"), "{}"); });
  EXPECT_EQ(msg.rfind(path("s.json") + ": cannot write file", 0), 0u) << msg;
  EXPECT_NE(msg.find(path("s.json.tmp")), std::string::npos) << msg;
}
