#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/detection/model_files.h"

#include <gtest/gtest.h>
#include "support/temp_dir.h"

#include <cstdio>
#include <fstream>
#include <string>

using namespace yolo_slam;
using namespace yolo_slam::detection;

namespace {

std::string models() { return joinPath(sharedDir(), "models"); }

// Expects `fn` to throw yolo_slam::Error whose message contains `needle`.
template <class F>
void expectError(F fn, const std::string& needle) {
  try {
    fn();
    FAIL() << "expected an Error mentioning " << needle;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}


}  // namespace

TEST(ModelFiles, ResolvesModelFolders) {
  ModelFiles m = resolveModel(joinPath(models(), "mnv2-yolov3-nano-voc"));
  EXPECT_EQ(m.format, ModelFormat::Darknet);
  EXPECT_NE(m.cfg.find("MobileNetV2-YOLOv3-Nano-voc.cfg"), std::string::npos);
  EXPECT_NE(m.weights.find("MobileNetV2-YOLOv3-Nano-voc.weights"), std::string::npos);
  EXPECT_NE(m.names.find("voc.names"), std::string::npos);
  auto names = readClassNames(m.names);
  ASSERT_EQ(names.size(), 20u);
  EXPECT_EQ(names[14], "person");  // VOC person = class 14

  ModelFiles c = resolveModel(m.cfg);  // a .cfg finds its weights and names beside it
  EXPECT_EQ(c.weights, m.weights);
  EXPECT_EQ(c.names, m.names);

  ModelFiles o = resolveModel(joinPath(models(), "nanodet-m/nanodet.onnx"));
  EXPECT_EQ(o.format, ModelFormat::Onnx);
  EXPECT_EQ(readClassNames(o.names).size(), 80u);
}

TEST(ModelFiles, ClearErrors) {
  expectError([] { resolveModel("/nonexistent/model/dir"); }, "/nonexistent/model/dir");
  expectError([] { resolveModel("/nonexistent/net.cfg"); }, "/nonexistent/net.cfg");
  // Two .onnx files in one folder: the user must say which.
  expectError([] { resolveModel(joinPath(models(), "nanodet-m")); }, "pass the one to use");
  test::TempDir tmp;
  const std::string dir = tmp.path();
  std::ofstream(joinPath(dir, "a.cfg")) << "[net]\nwidth=64\nheight=64\n";
  expectError([&] { resolveModel(dir); }, ".weights");
  std::ofstream(joinPath(dir, "a.weights")) << "x";
  expectError([&] { resolveModel(dir); }, ".names");
  std::ofstream(joinPath(dir, "a.names")) << "\n  \n";
  expectError([&] { readClassNames(joinPath(dir, "a.names")); }, "is empty");
  std::ofstream(joinPath(dir, "b.cfg")) << "[net]\nwidth=abc\n";
  expectError([&] { darknetInputSize(joinPath(dir, "b.cfg")); }, "b.cfg:2");
  std::ofstream(joinPath(dir, "bad.onnx")) << "this is not protobuf at all";
  expectError([&] { onnxInputSize(joinPath(dir, "bad.onnx")); }, "bad.onnx");
}

TEST(ModelFiles, NativeInputSizes) {
  EXPECT_EQ(darknetInputSize(joinPath(models(), "mnv2-yolov3-nano-voc/MobileNetV2-YOLOv3-Nano-voc.cfg")),
            cv::Size(320, 320));
  // Read from the ONNX protobuf (the two NanoDet exports differ).
  EXPECT_EQ(onnxInputSize(joinPath(models(), "nanodet-m/nanodet.onnx")), cv::Size(320, 320));
  EXPECT_EQ(onnxInputSize(joinPath(models(), "nanodet-m/nanodet_m.onnx")), cv::Size(416, 416));
}

TEST(ModelFiles, WeightsSizeMatchesCfgForSharedModels) {
  for (const char* dir : {"mnv2-yolov3-nano-voc", "mnv2-yolov3-nano-coco", "yolo-fastest-xl-voc",
                          "yolo-fastest-1.1-body"}) {
    ModelFiles m = resolveModel(joinPath(models(), dir));
    EXPECT_NO_THROW(checkDarknetWeights(m.cfg, m.weights)) << dir;
  }
}

TEST(ModelFiles, TruncatedWeightsAreRejected) {
  ModelFiles m = resolveModel(joinPath(models(), "mnv2-yolov3-nano-voc"));
  test::TempDir tmp;
  const std::string dir = tmp.path();
  std::ifstream in(m.weights, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string cut = joinPath(dir, "cut.weights");
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  expectError([&] { checkDarknetWeights(m.cfg, cut); }, "truncated");
  // The detector refuses it too (OpenCV alone would load it silently).
  std::ofstream(joinPath(dir, "net.cfg")) << std::ifstream(m.cfg).rdbuf();
  std::ofstream(joinPath(dir, "net.names")) << std::ifstream(m.names).rdbuf();
  std::rename(cut.c_str(), joinPath(dir, "net.weights").c_str());
  DetectorOptions opt;
  opt.model = dir;
  expectError([&] { YoloDetector d(opt); }, "net.weights");
}

TEST(DetectorOptions, LoadsKeysAndRejectsBadValues) {
  Config c = Config::fromString(
      "Detector.model: /abs/model\nDetector.inputWidth: 416\nDetector.inputHeight: 416\n"
      "Detector.letterbox: 1\nDetector.confThreshold: 0.5\nDetector.nmsThreshold: 0.4\n"
      "Detector.threads: 1\nDetector.dynamicClasses: [person, dog]\n",
      "det.yaml");
  DetectorOptions o = DetectorOptions::load(c);
  EXPECT_EQ(o.model, "/abs/model");
  EXPECT_EQ(o.input_width, 416);
  EXPECT_TRUE(o.letterbox);
  EXPECT_FLOAT_EQ(o.conf_threshold, 0.5f);
  EXPECT_FLOAT_EQ(o.nms_threshold, 0.4f);
  EXPECT_EQ(o.threads, 1);
  ASSERT_EQ(o.dynamic_classes.size(), 2u);
  EXPECT_EQ(o.dynamic_classes[1], "dog");

  DetectorOptions d = DetectorOptions::load(Config());
  EXPECT_EQ(d.model, defaultModelPath());
  EXPECT_EQ(d.dynamic_classes, (std::vector<std::string>{"person", "body"}));
  EXPECT_EQ(d.extra_models, defaultExtraModelPaths());

  // Extra models: "" (or a list of "") means none, relative paths are the package's.
  EXPECT_TRUE(DetectorOptions::load(Config::fromString("Detector.extraModels: \"\"\n", "x.yaml")).extra_models.empty());
  EXPECT_TRUE(DetectorOptions::load(Config::fromString("Detector.extraModels: [ \"\" ]\n", "x.yaml")).extra_models.empty());
  DetectorOptions e = DetectorOptions::load(
      Config::fromString("Detector.extraModels: [ /abs/a, models/b.cfg ]\n", "x.yaml"));
  EXPECT_EQ(e.extra_models, (std::vector<std::string>{"/abs/a", joinPath(packageDir(), "models/b.cfg")}));

  expectError([] { DetectorOptions::load(Config::fromString("Detector.confThreshold: 1.5\n", "x.yaml")); },
              "Detector.confThreshold");
  expectError([] { DetectorOptions::load(Config::fromString("Detector.inputWidth: 300\nDetector.inputHeight: 300\n", "x.yaml")); },
              "a multiple of 32");
  expectError([] { DetectorOptions::load(Config::fromString("Detector.threads: 0\n", "x.yaml")); },
              "Detector.threads");
}

TEST(DetectorOptions, DefaultModelFollowsEnvironment) {
  ::setenv("YOLO_SLAM_MODEL", "/some/where/model.cfg", 1);
  EXPECT_EQ(defaultModelPath(), "/some/where/model.cfg");
  ::unsetenv("YOLO_SLAM_MODEL");
  EXPECT_EQ(defaultModelPath(), joinPath(sharedDir(), "models/mnv2-yolov3-nano-voc"));
}

TEST(YoloDetector, UnknownDynamicClassIsAnError) {
  DetectorOptions opt;
  opt.model = joinPath(models(), "yolo-fastest-1.1-body");  // its only class is "body"
  opt.dynamic_classes = {"person"};
  expectError([&] { YoloDetector d(opt); }, "Detector.dynamicClasses");
}
