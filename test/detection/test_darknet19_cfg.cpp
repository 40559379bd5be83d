// The paper's Darknet19-YOLOv3 (models/darknet19-yolov3.cfg) loads in OpenCV DNN with random
// weights and predicts 13x13, 26x26 and 52x52 grids of 3 anchors x (4+1+1) values at 416x416.
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/detection/model_files.h"

#include <gtest/gtest.h>
#include "support/temp_dir.h"
#include <opencv2/dnn.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdint>
#include <fstream>
#include <random>
#include <set>

using namespace yolo_slam;
using namespace yolo_slam::detection;

namespace {

std::string cfgPath() { return joinPath(packageDir(), "models/darknet19-yolov3.cfg"); }

struct Conv {
  int in, out, k;
  bool bn;
};

// The network written out by hand from the paper (independent of the cfg parser under test).
std::vector<Conv> paperConvs() {
  std::vector<Conv> v;
  auto c = [&](int in, int out, int k, bool bn = true) { v.push_back({in, out, k, bn}); };
  // Darknet-19 (Fig. 3a)
  c(3, 32, 3); c(32, 64, 3);
  c(64, 128, 3); c(128, 64, 1); c(64, 128, 3);
  c(128, 256, 3); c(256, 128, 1); c(128, 256, 3);
  c(256, 512, 3); c(512, 256, 1); c(256, 512, 3); c(512, 256, 1); c(256, 512, 3);
  c(512, 1024, 3); c(1024, 512, 1); c(512, 1024, 3); c(1024, 512, 1); c(512, 1024, 3);
  // YOLOv3 head, stride 32
  c(1024, 512, 1); c(512, 1024, 3); c(1024, 512, 1); c(512, 1024, 3); c(1024, 512, 1);
  c(512, 1024, 3); c(1024, 18, 1, false);
  // stride 16: 1x1 on layer 27, upsample, concat with the 512-channel layer 16
  c(512, 256, 1);
  c(256 + 512, 256, 1); c(256, 512, 3); c(512, 256, 1); c(256, 512, 3); c(512, 256, 1);
  c(256, 512, 3); c(512, 18, 1, false);
  // stride 8: 1x1 on layer 39, upsample, concat with the 256-channel layer 10
  c(256, 128, 1);
  c(128 + 256, 128, 1); c(128, 256, 3); c(256, 128, 1); c(128, 256, 3); c(256, 128, 1);
  c(128, 256, 3); c(256, 18, 1, false);
  return v;
}

long long paramCount(const std::vector<Conv>& convs) {
  long long n = 0;
  for (const auto& c : convs) n += c.out * (c.bn ? 4LL : 1LL) + 1LL * c.out * c.in * c.k * c.k;
  return n;
}

// Writes Darknet weights: int32 major, minor, revision; uint64 seen; then per conv layer biases,
// [scales, rolling mean, rolling variance,] weights.
void writeRandomWeights(const std::string& path, const std::vector<Conv>& convs) {
  std::ofstream out(path, std::ios::binary);
  const int32_t ver[3] = {0, 2, 0};
  const uint64_t seen = 0;
  out.write(reinterpret_cast<const char*>(ver), sizeof(ver));
  out.write(reinterpret_cast<const char*>(&seen), sizeof(seen));
  std::mt19937 rng(7);
  auto put = [&](size_t n, float lo, float hi) {
    std::uniform_real_distribution<float> u(lo, hi);
    std::vector<float> v(n);
    for (auto& x : v) x = u(rng);
    out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(float)));
  };
  for (const auto& c : convs) {
    put(c.out, -0.1f, 0.1f);  // biases
    if (c.bn) {
      put(c.out, 0.5f, 1.5f);   // scales
      put(c.out, -0.1f, 0.1f);  // rolling mean
      put(c.out, 0.5f, 1.5f);   // rolling variance (> 0)
    }
    const float r = std::sqrt(3.f / float(c.in * c.k * c.k));  // keeps activations bounded
    put(size_t(c.out) * c.in * c.k * c.k, -r, r);
  }
}


}  // namespace

TEST(Darknet19Yolov3, CfgMatchesPaperParameterCount) {
  EXPECT_EQ(darknetInputSize(cfgPath()), cv::Size(416, 416));
  EXPECT_EQ(darknetParamCount(cfgPath()), paramCount(paperConvs()));
}

TEST(Darknet19Yolov3, LoadsWithRandomWeightsAndPredictsThreeScales) {
  const test::TempDir tmp;
  const std::string dir = tmp.path();
  const std::string weights = joinPath(dir, "darknet19-yolov3.weights");
  writeRandomWeights(weights, paperConvs());
  EXPECT_NO_THROW(checkDarknetWeights(cfgPath(), weights));

  cv::dnn::Net net = cv::dnn::readNetFromDarknet(cfgPath(), weights);
  ASSERT_FALSE(net.empty());
  cv::Mat img = cv::imread(joinPath(sharedDir(), "data/images/person.jpg"));
  ASSERT_FALSE(img.empty());
  net.setInput(cv::dnn::blobFromImage(img, 1 / 255.0, cv::Size(416, 416), cv::Scalar(), true, false));
  std::vector<cv::Mat> outs;
  net.forward(outs, net.getUnconnectedOutLayersNames());
  ASSERT_EQ(outs.size(), 3u);
  std::multiset<int> rows;
  for (const auto& o : outs) {
    ASSERT_EQ(o.dims, 2);
    EXPECT_EQ(o.cols, 4 + 1 + 1);  // 18 channels per cell = 3 anchors x 6
    rows.insert(o.rows);
    EXPECT_TRUE(cv::checkRange(o));  // no NaN/inf from the random weights
  }
  EXPECT_EQ(rows, (std::multiset<int>{13 * 13 * 3, 26 * 26 * 3, 52 * 52 * 3}));

  // The detector runs it too (with a one-class names file) and keeps boxes inside the image.
  std::ofstream(joinPath(dir, "person.names")) << "person\n";
  std::ofstream(joinPath(dir, "darknet19-yolov3.cfg")) << std::ifstream(cfgPath()).rdbuf();
  DetectorOptions opt;
  opt.model = dir;
  opt.conf_threshold = 0.01f;
  opt.input_width = opt.input_height = 160;  // any multiple of 32; small keeps the test quick
  YoloDetector det(opt);
  EXPECT_EQ(det.inputSize(), cv::Size(160, 160));
  for (const auto& b : det.detect(img)) {
    EXPECT_EQ(b.label, "person");
    EXPECT_GE(b.score, opt.conf_threshold);
    EXPECT_GE(b.rect.x, 0.f);
    EXPECT_GE(b.rect.y, 0.f);
    EXPECT_LE(b.rect.x + b.rect.width, float(img.cols) + 1e-3f);
    EXPECT_LE(b.rect.y + b.rect.height, float(img.rows) + 1e-3f);
  }
}

TEST(Darknet19Yolov3, WeightsOfAnotherNetworkAreRejected) {
  const test::TempDir tmp;
  const std::string dir = tmp.path();
  const std::string weights = joinPath(dir, "w.weights");
  auto convs = paperConvs();
  convs.pop_back();  // a file missing the last detection kernel
  writeRandomWeights(weights, convs);
  EXPECT_THROW(checkDarknetWeights(cfgPath(), weights), Error);
}
