// The yolo_slam_detect command line: JSON output, drawing, one-line errors with exit code 1.
#include "yolo_slam/common/paths.h"

#include <gtest/gtest.h>
#include "support/temp_dir.h"

#include <opencv2/imgcodecs.hpp>

#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

using namespace yolo_slam;

namespace {

std::string tool() { return joinPath(YOLO_SLAM_BIN_DIR, "yolo_slam_detect"); }

// Runs a shell command, returning its exit code and stdout+stderr.
int run(const std::string& cmd, std::string& out) {
  out.clear();
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return -1;
  std::array<char, 4096> buf;
  while (size_t n = std::fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  int status = ::pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST(DetectTool, JsonAndDrawing) {
  if (!fileExists(tool())) GTEST_SKIP() << tool() << " not built (make yolo_slam_detect)";
  test::TempDir tmp;
  const std::string img = joinPath(sharedDir(), "data/images/person.jpg");
  const std::string png = joinPath(tmp.path(), "out.png");
  std::string out;
  ASSERT_EQ(run(tool() + " --json --draw " + png + " " + img, out), 0) << out;
  EXPECT_EQ(out.rfind("[{\"image\":\"" + img + "\",\"boxes\":[{\"class\":\"person\",\"score\":", 0), 0u)
      << out;
  EXPECT_NE(out.find("\"x1\":"), std::string::npos);
  EXPECT_NE(out.find("\"y2\":"), std::string::npos);
  cv::Mat drawn = cv::imread(png);
  EXPECT_EQ(drawn.size(), cv::Size(640, 424));
}

TEST(DetectTool, ErrorsAreOneLine) {
  if (!fileExists(tool())) GTEST_SKIP() << tool() << " not built (make yolo_slam_detect)";
  std::string out;
  EXPECT_EQ(run(tool() + " --model /nonexistent/m.cfg x.png", out), 1);
  EXPECT_EQ(out.rfind("error: ", 0), 0u) << out;
  EXPECT_NE(out.find("/nonexistent/m.cfg"), std::string::npos) << out;
  EXPECT_EQ(out.find('\n'), out.size() - 1) << out;
  EXPECT_EQ(run(tool() + " /nonexistent/image.png", out), 1);
  EXPECT_NE(out.find("error: cannot read image /nonexistent/image.png"), std::string::npos) << out;
  EXPECT_EQ(run(tool() + " --single-model --extra-model m.cfg x.png", out), 1);
  EXPECT_NE(out.find("exclude each other"), std::string::npos) << out;
  EXPECT_EQ(run(tool() + " --extra-model /nonexistent/extra.cfg " + joinPath(sharedDir(), "data/images/person.jpg"), out), 1);
  EXPECT_NE(out.find("/nonexistent/extra.cfg"), std::string::npos) << out;
  EXPECT_NE(out.find("Detector.extraModels"), std::string::npos) << out;
  EXPECT_EQ(run(tool() + " --conf abc x.png", out), 1);
  EXPECT_NE(out.find("--conf"), std::string::npos) << out;
}
