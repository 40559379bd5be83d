#pragma once
// Person (dynamic object) detection on the CPU through OpenCV DNN: Darknet YOLO models
// (cfg + weights, e.g. the paper's Darknet19-YOLOv3 in models/darknet19-yolov3.cfg) and ONNX
// models (YOLO-style rows or NanoDet heads).
#include "yolo_slam/detection/box.h"

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace yolo_slam {

class Config;

namespace detection {

// Model used when none is configured: env YOLO_SLAM_MODEL if set, else
// sharedDir()/models/mnv2-yolov3-nano-voc.
std::string defaultModelPath();
// Extra models used when none are configured: sharedDir()/models/yolo-fastest-1.1-body.
std::vector<std::string> defaultExtraModelPaths();

struct DetectorOptions {
  // A model folder (holding one .cfg + .weights, or one .onnx, and one .names file), a .cfg
  // (weights and names are looked up beside it) or a .onnx file.
  std::string model = defaultModelPath();
  int input_width = 0, input_height = 0;  // 0 = the model's native size
  // Keep the aspect ratio with padding instead of stretching: on the synthetic walking presets
  // dynamic recall +0.1 to +1.0 points, false boxes on static_xyz 314 -> 57; on the real TUM
  // frame with a person mask 96.3 % of the mask covered instead of 93.4 % (docs/ablation.md).
  bool letterbox = true;
  // Darknet models: OpenCV 4.6's region layer zeroes class scores <= 0.2 itself, so lower
  // thresholds act like 0.2 there.
  float conf_threshold = 0.3f;
  float nms_threshold = 0.45f;
  // cv::setNumThreads before each forward pass. OpenCV's thread count is process-wide: it also
  // applies to other OpenCV calls made meanwhile in other threads.
  int threads = 2;
  // OpenCV's thread pool is sized once per process; beyond this it only costs memory (and tens of
  // thousands of threads crash at exit).
  static constexpr int kMaxThreads = 64;
  // Class names kept, looked up in each model's names file; every model must know one of them
  // ("body" is the only class of yolo-fastest-1.1-body).
  std::vector<std::string> dynamic_classes{"person", "body"};
  // Further models run on every frame beside `model`, same settings; their boxes join the main
  // model's, and boxes of different models overlapping by more than nms_threshold (IoU) are one
  // person, merged into the box enclosing both (mergeOverlapping). The default person-only
  // model finds people cut by the image border whom the main model misses: dynamic recall
  // +2 to +4 points on the synthetic walking presets for about 8 ms per frame
  // (docs/ablation.md). Empty: the main model alone.
  std::vector<std::string> extra_models = defaultExtraModelPaths();

  // Keys: Detector.model, Detector.extraModels (a list; "" or [""] for none),
  // Detector.inputWidth, Detector.inputHeight, Detector.letterbox, Detector.confThreshold,
  // Detector.nmsThreshold, Detector.threads, Detector.dynamicClasses.
  // Throws yolo_slam::Error naming the file and key on out-of-range values.
  static DetectorOptions load(const Config& cfg);
  // The loader's rules, for options set in code; throws yolo_slam::Error prefixed by `where`.
  void validate(const std::string& where = "DetectorOptions") const;
};

class Detector {
 public:
  virtual ~Detector();
  // Boxes of the dynamic classes in `bgr` (CV_8UC3 BGR; grey or BGRA are converted), in pixels
  // clipped to the image, sorted by decreasing score.
  virtual Boxes detect(const cv::Mat& bgr) = 0;
  // What runs, for logs: head, input size, classes and model files.
  virtual std::string description() const = 0;
};

// Thread-compatible, not thread-safe: one instance may be used by one thread at a time (the
// cv::dnn::Net inside keeps per-forward state). Use one instance per thread to run in parallel.
class YoloDetector : public Detector {
 public:
  // Loads and checks the model (one warm-up forward pass). Throws yolo_slam::Error naming the
  // file when a model file is missing, corrupt, or does not match its names file.
  explicit YoloDetector(const DetectorOptions& options);
  ~YoloDetector() override;
  YoloDetector(const YoloDetector&) = delete;
  YoloDetector& operator=(const YoloDetector&) = delete;

  Boxes detect(const cv::Mat& bgr) override;

  const DetectorOptions& options() const;
  cv::Size inputSize() const;                     // network input actually used
  const std::vector<std::string>& classNames() const;
  std::string description() const override;      // e.g. "darknet-yolo 320x320, 20 classes, ..."

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Boxes sorted by decreasing score; a box overlapping an earlier (higher-scored) kept box's own
// rectangle by more than `iou` is merged into it: the kept box grows to enclose both and keeps
// its label and score. Two models boxing one person rarely agree on the limbs, so the
// enclosing box covers more of them. Overlap is never tested against a grown box.
Boxes mergeOverlapping(Boxes boxes, float iou);

// Several models on every frame, their boxes merged by mergeOverlapping(nms_threshold). Same
// threading contract as YoloDetector; the models run one after the other.
class MultiModelDetector : public Detector {
 public:
  // Loads options.model and every options.extra_models entry with the other options. Throws
  // yolo_slam::Error naming the file (and Detector.extraModels for an extra one) on failure.
  explicit MultiModelDetector(const DetectorOptions& options);
  Boxes detect(const cv::Mat& bgr) override;
  std::string description() const override;  // the models' descriptions joined by "; "

 private:
  std::vector<std::unique_ptr<YoloDetector>> models_;
  float merge_iou_;
};

// A YoloDetector when options.extra_models is empty, else a MultiModelDetector.
std::unique_ptr<Detector> makeDetector(const DetectorOptions& options);

}  // namespace detection
}  // namespace yolo_slam
