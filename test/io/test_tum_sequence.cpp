#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/io/tum_sequence.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sys/stat.h>
#include <unistd.h>

using namespace yolo_slam;

namespace {
const std::string kSeq = "data/tum/rgbd_dataset_freiburg3_walking_xyz";

// A fresh temporary folder, removed with its files at the end of the test.
struct TempDir {
  std::string path;
  TempDir() {
    char tmpl[] = "/tmp/ys_tumseq_XXXXXX";
    path = ::mkdtemp(tmpl);
  }
  ~TempDir() { std::system(("rm -rf '" + path + "'").c_str()); }
  std::string file(const std::string& name, const std::string& text) const {
    std::string p = joinPath(path, name);
    std::ofstream(p) << text;
    return p;
  }
};
}  // namespace

TEST(TumSequence, RealFolderUsesAssociationsFile) {
  const std::string dir = joinPath(sharedDir(), kSeq);
  io::TumSequence seq = io::TumSequence::open(dir);
  EXPECT_TRUE(seq.fromAssociationsFile());
  ASSERT_EQ(seq.size(), 2u);
  EXPECT_DOUBLE_EQ(seq.frames()[0].rgb_stamp, 1341846313.592026);
  EXPECT_DOUBLE_EQ(seq.frames()[0].depth_stamp, 1341846313.592088);
  EXPECT_EQ(seq.frames()[0].rgb_path, joinPath(dir, "rgb/1341846313.592026.png"));
  EXPECT_EQ(seq.frames()[1].depth_path, joinPath(dir, "depth/1341846316.570146.png"));
  ASSERT_TRUE(seq.hasGroundTruth());
  EXPECT_EQ(seq.groundTruth().size(), 2884u);
  EXPECT_DOUBLE_EQ(seq.groundTruth().front().stamp, 1341846313.6378);

  cv::Mat rgb = seq.loadRgb(0);
  EXPECT_EQ(rgb.type(), CV_8UC3);
  EXPECT_EQ(rgb.cols, 640);
  EXPECT_EQ(rgb.rows, 480);
  cv::Mat depth = seq.loadDepth(0, 5000.0);
  EXPECT_EQ(depth.type(), CV_32FC1);
  double mn, mx;
  cv::minMaxLoc(depth, &mn, &mx);
  EXPECT_GE(mn, 0.0);
  EXPECT_GT(mx, 0.5);   // walking_xyz: desk and people 1-4 m away
  EXPECT_LT(mx, 13.2);  // 65535 / 5000
  EXPECT_THROW(seq.loadRgb(2), Error);
}

TEST(TumSequence, RealListsAssociateLikeAssociatePy) {
  // Same rgb.txt/depth.txt without associations.txt: associate.py gives the same two pairs
  // (rgb 313.553992 is 0.038 s from the nearest depth, above 0.02 s).
  const std::string dir = joinPath(sharedDir(), kSeq);
  TempDir t;
  std::system(("cp '" + dir + "/rgb.txt' '" + dir + "/depth.txt' '" + t.path + "/'").c_str());
  io::TumSequence seq = io::TumSequence::open(t.path);
  EXPECT_FALSE(seq.fromAssociationsFile());
  EXPECT_FALSE(seq.hasGroundTruth());
  EXPECT_THROW(seq.groundTruth(), Error);
  io::TumSequence real = io::TumSequence::open(dir);
  ASSERT_EQ(seq.size(), real.size());
  for (size_t i = 0; i < seq.size(); ++i) {
    EXPECT_EQ(seq.frames()[i].rgb_stamp, real.frames()[i].rgb_stamp);
    EXPECT_EQ(seq.frames()[i].depth_stamp, real.frames()[i].depth_stamp);
  }
}

TEST(TumSequence, TempFolderWithListsOnly) {
  TempDir t;
  t.file("rgb.txt", "# color images\n# timestamp filename\n1.00 rgb/1.png\n1.05 rgb/2.png\n2.00 rgb/3.png\n");
  t.file("depth.txt", "# depth\n1.01 depth/1.png\n1.049 depth/2.png\n3.0 depth/3.png\n");
  ::mkdir((t.path + "/depth").c_str(), 0755);
  cv::imwrite(t.path + "/depth/2.png", cv::Mat(3, 3, CV_16UC1, cv::Scalar(5000)));
  io::TumSequence seq = io::TumSequence::open(t.path, 0.02);
  ASSERT_EQ(seq.size(), 2u);
  EXPECT_DOUBLE_EQ(seq.frames()[0].rgb_stamp, 1.00);
  EXPECT_DOUBLE_EQ(seq.frames()[0].depth_stamp, 1.01);
  EXPECT_DOUBLE_EQ(seq.frames()[1].rgb_stamp, 1.05);
  EXPECT_DOUBLE_EQ(seq.frames()[1].depth_stamp, 1.049);
  EXPECT_EQ(seq.dir(), t.path);
  EXPECT_FLOAT_EQ(seq.loadDepth(1, 5000.0).at<float>(1, 1), 1.f);
  // rgb/1.png does not exist: the error names it.
  try {
    seq.loadRgb(0);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("rgb/1.png"), std::string::npos) << e.what();
  }
}

TEST(TumSequence, BadFoldersAndListsNameFileAndLine) {
  EXPECT_THROW(io::TumSequence::open("/tmp/ys_no_such_sequence_folder"), Error);
  TempDir t;
  EXPECT_THROW(io::TumSequence::open(t.path), Error);  // no lists at all
  std::string rgb = t.file("rgb.txt", "1.0 rgb/1.png\n1.1\n");
  t.file("depth.txt", "1.0 depth/1.png\n");
  try {
    io::TumSequence::open(t.path);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(rgb + ":2:"), std::string::npos) << e.what();
  }
  t.file("rgb.txt", "5.0 rgb/1.png\n");  // nothing within 0.02 s
  EXPECT_THROW(io::TumSequence::open(t.path), Error);
  std::string assoc = t.file("associations.txt", "1.0 rgb/1.png 1.0 depth/1.png\n1.0 rgb/1.png nan depth/1.png\n");
  try {
    io::TumSequence::open(t.path);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(assoc + ":2:"), std::string::npos) << e.what();
  }
}
