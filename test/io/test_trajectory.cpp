#include "yolo_slam/common/error.h"
#include "yolo_slam/io/text_table.h"
#include "yolo_slam/io/trajectory.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <unistd.h>

using namespace yolo_slam;

namespace {

std::string tempPath(const std::string& name) {
  return "/tmp/ys_io_test_" + std::to_string(::getpid()) + "_" + name;
}

std::string writeText(const std::string& name, const std::string& text) {
  std::string p = tempPath(name);
  std::ofstream(p) << text;
  return p;
}

// Expects readTrajectory(path) to throw an Error whose message contains `needle`.
void expectError(const std::string& path, const std::string& needle) {
  try {
    io::readTrajectory(path);
    ADD_FAILURE() << "expected an error for " << path;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(Trajectory, ParsesCommentsBlankLinesTabsAndCommas) {
  std::string p = writeText("ok.txt",
                            "# ground truth trajectory\n"
                            "# timestamp tx ty tz qx qy qz qw\n"
                            "\n"
                            "1.5 1 2 3 0 0 0 1\r\n"
                            "  # indented comment\n"
                            "2.5\t4,5 6 0 0 0.70710678 0.70710678\n");
  Trajectory t = io::readTrajectory(p);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_DOUBLE_EQ(t[0].stamp, 1.5);
  EXPECT_TRUE(t[0].T_wc.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE(t[0].T_wc.linear().isIdentity(1e-12));
  EXPECT_DOUBLE_EQ(t[1].stamp, 2.5);
  EXPECT_TRUE(t[1].T_wc.translation().isApprox(Eigen::Vector3d(4, 5, 6)));
  // 90 degrees about z: x axis maps to y.
  EXPECT_TRUE((t[1].T_wc.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-7));
  std::remove(p.c_str());
}

TEST(Trajectory, UnnormalisedQuaternionIsNormalised) {
  std::string p = writeText("unnorm.txt", "0 0 0 0 0 0 0 2\n");
  Trajectory t = io::readTrajectory(p);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_TRUE(t[0].T_wc.linear().isIdentity(1e-12));
  std::remove(p.c_str());
}

TEST(Trajectory, MalformedLinesNameFileAndLine) {
  std::string few = writeText("few.txt", "# c\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n");
  expectError(few, few + ":3:");
  std::string word = writeText("word.txt", "1 0 0 0 0 0 0 1\n\n2 0 x 0 0 0 0 1\n");
  expectError(word, word + ":3:");
  expectError(word, "'x'");
  std::string nan = writeText("nan.txt", "1 0 0 nan 0 0 0 1\n");
  expectError(nan, nan + ":1:");
  expectError(nan, "NaN");
  std::string inf = writeText("inf.txt", "1 0 0 0 0 0 0 1\n2 inf 0 0 0 0 0 1\n");
  expectError(inf, inf + ":2:");
  std::string zeroq = writeText("zeroq.txt", "1 0 0 0 0 0 0 0\n");
  expectError(zeroq, zeroq + ":1:");
  std::string trailing = writeText("trail.txt", "1 0 0 0 0 0 0 1.0abc\n");
  expectError(trailing, trailing + ":1:");
  std::string many = writeText("many.txt", "1 0 0 0 0 0 0 1 9\n");
  expectError(many, many + ":1:");
  for (auto* p : {&few, &word, &nan, &inf, &zeroq, &trailing, &many}) std::remove(p->c_str());
}

TEST(Trajectory, MissingFileNamesFile) {
  expectError(tempPath("does_not_exist.txt"), "does_not_exist.txt");
  expectError("/tmp", "/tmp");
}

TEST(Trajectory, EmptyFileGivesEmptyTrajectory) {
  std::string p = writeText("empty.txt", "# only comments\n\n");
  EXPECT_TRUE(io::readTrajectory(p).empty());
  std::remove(p.c_str());
}

TEST(Trajectory, WriteReadRoundTripAndAtomic) {
  Trajectory t;
  for (int i = 0; i < 5; ++i) {
    StampedPose p;
    p.stamp = 1341846313.592026 + i * 0.033333;
    p.T_wc = makePose(Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * i - 0.5, Eigen::Vector3d(1, 2, 3).normalized())),
                      Eigen::Vector3d(0.1 * i, -1.234567891, 1e-3 * i));
    t.push_back(p);
  }
  std::string path = tempPath("rt.txt");
  io::writeTrajectory(path, t);
  EXPECT_FALSE(std::ifstream(path + ".tmp").good());
  Trajectory r = io::readTrajectory(path);
  ASSERT_EQ(r.size(), t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    EXPECT_NEAR(r[i].stamp, t[i].stamp, 1e-6);  // %.6f
    EXPECT_TRUE(r[i].T_wc.translation().isApprox(t[i].T_wc.translation(), 1e-8));
    EXPECT_TRUE(r[i].T_wc.linear().isApprox(t[i].T_wc.linear(), 1e-8));
  }
  std::remove(path.c_str());
}

TEST(Trajectory, WriteToMissingFolderThrowsAndLeavesNothing) {
  std::string path = tempPath("nofolder/x.txt");
  EXPECT_THROW(io::writeTrajectory(path, Trajectory(1)), Error);
  EXPECT_FALSE(std::ifstream(path).good());
}

TEST(TextTable, ParseFiniteDouble) {
  EXPECT_DOUBLE_EQ(io::parseFiniteDouble("1e-3", "f", 1, "v"), 1e-3);
  EXPECT_THROW(io::parseFiniteDouble("", "f", 1, "v"), Error);
  EXPECT_THROW(io::parseFiniteDouble("1e999", "f", 1, "v"), Error);
  EXPECT_THROW(io::parseFiniteDouble("-nan", "f", 1, "v"), Error);
}
