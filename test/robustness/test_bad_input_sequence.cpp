// yolo_slam_run on sequences with bad files: saturated depth, depth beyond DepthMaxRange, a bad
// line in the optional groundtruth.txt, a folder in place of an image, lists that never pair.
// Each ends with an exit code (never a signal) and a message naming the file; what would have
// been a silently wrong result is refused or warned about.
#include "robustness/tool_run.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cctype>
#include <random>

using namespace robustness;
using yolo_slam::joinPath;

namespace {

class BadSequence : public SequenceSuite {};

// Every depth image of `seq` replaced by a constant 16-bit code.
void fillDepth(const std::string& seq, uint16_t code) {
  for (const auto& entry : std::filesystem::directory_iterator(joinPath(seq, "depth")))
    ASSERT_TRUE(cv::imwrite(entry.path().string(), cv::Mat(480, 640, CV_16UC1, cv::Scalar(code))));
}

std::string firstDepthFile(const std::string& seq) {
  std::ifstream in(joinPath(seq, "depth.txt"));
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    return joinPath(seq, line.substr(line.find(' ') + 1));
  }
  return "";
}

}  // namespace

TEST_F(BadSequence, SaturatedDepthIsNoDepthAndNamedPerFile) {
  const std::string seq = freshSequence();
  fillDepth(seq, 65535);
  const Outcome r = runSlam(seq);
  ASSERT_TRUE(r.exited()) << r;
  // Before issue 22 this tracked a plane at 13.1 m (ATE 0.395 m on TUM instead of 3 mm).
  EXPECT_TRUE(contains(r.err, firstDepthFile(seq) + ": every reading is 65535")) << r;
  EXPECT_TRUE(contains(r.err, "(tracked without depth)")) << r;
  EXPECT_EQ(dataLines(joinPath(outDir(), "CameraTrajectory.txt")), 0u) << "no pose from no depth\n" << r;
  EXPECT_NE(r.exit_code, 0) << "a run that tracked nothing does not exit 0\n" << r;
}

TEST_F(BadSequence, DepthBeyondTheRangeIsNoDepth) {
  const std::string seq = freshSequence();
  fillDepth(seq, 60000);  // 12 m with factor 5000: beyond the default DepthMaxRange of 10 m
  const Outcome r = runSlam(seq);
  ASSERT_TRUE(r.exited()) << r;
  EXPECT_NE(r.exit_code, 0) << r;
  EXPECT_EQ(dataLines(joinPath(outDir(), "CameraTrajectory.txt")), 0u) << r;
  // DepthMaxRange is a setting: a range that covers 12 m lets the same frames track.
  const Outcome wide = runSlam(seq, {"--set", "DepthMaxRange=15"});
  ASSERT_EQ(wide.exit_code, 0) << wide;
  EXPECT_GT(dataLines(joinPath(outDir(), "CameraTrajectory.txt")), 0u) << wide;
}

TEST_F(BadSequence, BadGroundTruthLineWarnsAndRunsWithoutAte) {
  const std::string seq = freshSequence();
  const std::string gt = joinPath(seq, "groundtruth.txt");
  std::string text = readAll(gt);
  text += "1305031102.175304 1.0 2.0\n";  // three of eight values
  size_t line = 0;
  for (char c : text) line += c == '\n';
  writeAll(gt, text);
  const Outcome r = runSlam(seq);
  ASSERT_TRUE(r.exited()) << r;
  EXPECT_EQ(r.exit_code, 0) << "ground truth is optional: a bad line costs the ATE, not the run\n" << r;
  EXPECT_TRUE(contains(r.err, gt + ":" + std::to_string(line) + ": expected 8 values")) << r;
  EXPECT_TRUE(contains(r.err, "run without ground truth (no ATE)")) << r;
  EXPECT_GT(dataLines(joinPath(outDir(), "CameraTrajectory.txt")), 0u) << r;
}

TEST_F(BadSequence, FolderInPlaceOfAnImageIsNamedAsSuch) {
  const std::string seq = freshSequence();
  std::ifstream in(joinPath(seq, "rgb.txt"));
  std::string rgb;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') {
      rgb = joinPath(seq, line.substr(line.find(' ') + 1));
      break;
    }
  std::filesystem::remove(rgb);
  std::filesystem::create_directory(rgb);
  const Outcome r = runSlam(seq);
  ASSERT_TRUE(r.exited()) << r;
  EXPECT_TRUE(contains(r.err, rgb + ": is a folder, expected an rgb image file")) << r;
}

TEST_F(BadSequence, ListsThatNeverPairSayWhatToCheck) {
  const std::string seq = freshSequence();
  std::filesystem::remove(joinPath(seq, "associations.txt"));  // pair rgb.txt with depth.txt
  const std::string depth_txt = joinPath(seq, "depth.txt");
  std::ifstream in(depth_txt);
  std::string shifted;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const size_t sp = line.find(' ');
    shifted += std::to_string(std::stod(line.substr(0, sp)) + 1000.0) + line.substr(sp) + "\n";
  }
  in.close();
  writeAll(depth_txt, shifted);
  const Outcome r = runSlam(seq);
  ASSERT_TRUE(r.exited()) << r;
  EXPECT_EQ(r.exit_code, 1) << r;
  EXPECT_TRUE(contains(r.err, joinPath(seq, "rgb.txt") + ": no rgb stamp has a depth stamp in " + depth_txt)) << r;
  EXPECT_TRUE(contains(r.err, "associations.txt")) << r;
  EXPECT_FALSE(contains(r.err, "raise the max difference")) << "there is no such option\n" << r;
}

TEST_F(BadSequence, RandomVocabularyFileIsNamedWithoutBinaryBytes) {
  std::mt19937 rng(7);
  std::string junk(4096, '\0');
  for (char& c : junk) c = static_cast<char>(rng());
  junk[0] = '1';  // not the binary magic: read as a text vocabulary
  const std::string voc = path("random.voc");
  writeAll(voc, junk);
  const Outcome r = runTool("yolo_slam_run", {"--sequence", freshSequence(), "--out", path("voc_out"), "--vocabulary", voc},
                            path("voc"));
  ASSERT_TRUE(r.exited()) << r;
  EXPECT_EQ(r.exit_code, 1) << r;
  EXPECT_TRUE(contains(r.err, voc + ": not a vocabulary")) << r;
  EXPECT_TRUE(std::all_of(r.err.begin(), r.err.end(),
                          [](char c) { return c == '\n' || std::isprint(static_cast<unsigned char>(c)); }))
      << "raw bytes in the message:\n" << r;
}
