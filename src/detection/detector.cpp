#include "yolo_slam/detection/detector.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/detection/decode.h"
#include "yolo_slam/detection/model_files.h"

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdlib>
#include <map>

namespace yolo_slam {
namespace detection {

std::string defaultModelPath() {
  const char* env = std::getenv("YOLO_SLAM_MODEL");
  if (env && *env) return env;
  return joinPath(sharedDir(), "models/mnv2-yolov3-nano-voc");
}

std::vector<std::string> defaultExtraModelPaths() {
  return {joinPath(sharedDir(), "models/yolo-fastest-1.1-body")};
}

namespace {

const OptionTable<DetectorOptions>& detectorFields() {
  using O = DetectorOptions;
  static const OptionTable<O> table = {
      {"Detector.inputWidth", &O::input_width, Range::atLeast(0)},
      {"Detector.inputHeight", &O::input_height, Range::atLeast(0)},
      {"Detector.letterbox", &O::letterbox},
      {"Detector.confThreshold", &O::conf_threshold, Range::open(0, 1)},
      {"Detector.nmsThreshold", &O::nms_threshold, Range::openClosed(0, 1)},
      {"Detector.threads", &O::threads, Range::closed(1, O::kMaxThreads)},
  };
  return table;
}

// Rules across fields and on the class list, which the table cannot state.
void checkInputAndClasses(const DetectorOptions& o, const std::string& where) {
  for (const auto& [key, v] : {std::make_pair("Detector.inputWidth", o.input_width),
                               std::make_pair("Detector.inputHeight", o.input_height)})
    if (v % 32) rejectOption(where, key, "a multiple of 32", std::to_string(v));
  if ((o.input_width == 0) != (o.input_height == 0))
    rejectOption(where, "Detector.inputHeight",
                 "0 exactly when Detector.inputWidth is 0 (native size)",
                 std::to_string(o.input_height));
  if (o.dynamic_classes.empty())
    rejectOption(where, "Detector.dynamicClasses", "a list of at least one class name", "[]");
}

}  // namespace

DetectorOptions DetectorOptions::load(const Config& cfg) {
  DetectorOptions o;
  // Empty keeps the default (YOLO_SLAM_MODEL or the shared model); a relative path is taken
  // relative to the package folder, like the other files a settings file names.
  const std::string model = cfg.getString("Detector.model", "");
  if (!model.empty()) o.model = model.front() == '/' ? model : joinPath(packageDir(), model);
  if (cfg.has("Detector.extraModels")) {
    o.extra_models.clear();
    for (const auto& m : cfg.getStringList("Detector.extraModels", {}))
      if (!m.empty()) o.extra_models.push_back(m.front() == '/' ? m : joinPath(packageDir(), m));
  }
  readOptions(cfg, o, detectorFields());
  o.dynamic_classes = cfg.getStringList("Detector.dynamicClasses", o.dynamic_classes);
  checkInputAndClasses(o, configName(cfg));
  return o;
}

void DetectorOptions::validate(const std::string& where) const {
  checkOptions(*this, where, detectorFields());
  checkInputAndClasses(*this, where);
}

Detector::~Detector() = default;

namespace {

enum class Head { DarknetYolo, OnnxYolo, NanoDet };

const char* headName(Head h) {
  switch (h) {
    case Head::DarknetYolo: return "darknet-yolo";
    case Head::OnnxYolo: return "onnx-yolo";
    case Head::NanoDet: return "onnx-nanodet";
  }
  return "?";
}

int lastDim(const cv::Mat& m) { return m.size[m.dims - 1]; }
int rowCount(const cv::Mat& m) { return int(m.total() / lastDim(m)); }

}  // namespace

struct YoloDetector::Impl {
  DetectorOptions opt;
  ModelFiles files;
  std::vector<std::string> names;
  std::vector<bool> keep;
  cv::dnn::Net net;
  cv::Size input;
  Head head = Head::DarknetYolo;
  std::vector<std::string> out_names;
  // NanoDet: (cls output index, reg output index, stride) per level, paired by shape because
  // some exports name their outputs inconsistently with their contents.
  struct Level { int cls, reg, stride; };
  std::vector<Level> levels;

  std::string modelFile() const {
    return files.format == ModelFormat::Darknet ? files.cfg + " + " + files.weights : files.weights;
  }

  cv::Mat blob(const cv::Mat& fitted) const {
    if (head == Head::NanoDet) {
      // NanoDet expects BGR normalised by its ImageNet mean/std (in 0..255 units).
      cv::Mat f;
      fitted.convertTo(f, CV_32F);
      f -= cv::Scalar(103.53, 116.28, 123.675);
      cv::multiply(f, cv::Scalar(1 / 57.375, 1 / 57.12, 1 / 58.395), f);
      return cv::dnn::blobFromImage(f, 1.0, input, cv::Scalar(), false, false);
    }
    return cv::dnn::blobFromImage(fitted, 1 / 255.0, input, cv::Scalar(), true, false);
  }

  void setThreads() const {
    if (cv::getNumThreads() != opt.threads) cv::setNumThreads(opt.threads);
  }

  // Runs one forward pass on a grey frame and picks the decoder from the output shapes.
  void inspectOutputs() {
    cv::Mat grey(input, CV_8UC3, cv::Scalar::all(114));
    std::vector<cv::Mat> outs;
    net.setInput(blob(grey));
    net.forward(outs, out_names);
    const int n_cls = int(names.size());
    bool all_rows = !outs.empty();
    for (const auto& o : outs) all_rows = all_rows && lastDim(o) == 5 + n_cls;
    if (files.format == ModelFormat::Darknet) {
      for (const auto& o : outs)
        if (lastDim(o) != 5 + n_cls)
          throw Error("Darknet model " + files.cfg + " predicts " + std::to_string(lastDim(o) - 5) +
                      " classes but names file " + files.names + " lists " + std::to_string(n_cls) +
                      "; use the names file that belongs to this model");
      head = Head::DarknetYolo;
      return;
    }
    if (all_rows) {
      head = Head::OnnxYolo;
      return;
    }
    // NanoDet: pairs (cells x C scores, cells x 4*bins distances) with equal cell counts.
    std::map<int, std::vector<int>> by_rows;
    for (int i = 0; i < int(outs.size()); ++i) by_rows[rowCount(outs[i])].push_back(i);
    levels.clear();
    for (const auto& [cells, idx] : by_rows) {
      if (idx.size() != 2) break;
      int a = idx[0], b = idx[1];
      if (lastDim(outs[a]) != n_cls) std::swap(a, b);
      if (lastDim(outs[a]) != n_cls || lastDim(outs[b]) % 4 != 0) break;
      int stride = 0;
      for (int s = 4; s <= 256 && !stride; s *= 2)
        if (((input.width + s - 1) / s) * ((input.height + s - 1) / s) == cells) stride = s;
      if (!stride) break;
      levels.push_back({a, b, stride});
    }
    if (levels.empty() || levels.size() * 2 != outs.size()) {
      std::string shapes;
      for (const auto& o : outs)
        shapes += " " + std::to_string(rowCount(o)) + "x" + std::to_string(lastDim(o));
      throw Error("ONNX model " + files.weights + ": output layout" + shapes +
                  " is neither YOLO rows (5+" + std::to_string(n_cls) + " columns, from " +
                  files.names + ") nor a NanoDet head; use a supported model");
    }
    head = Head::NanoDet;
  }
};

YoloDetector::YoloDetector(const DetectorOptions& options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.opt = options;
  m.opt.validate();
  m.files = resolveModel(options.model);
  m.names = readClassNames(m.files.names);
  m.keep.assign(m.names.size(), false);
  std::string listed;
  for (const auto& want : options.dynamic_classes) {
    listed += (listed.empty() ? "" : ", ") + want;
    for (size_t c = 0; c < m.names.size(); ++c)
      if (m.names[c] == want) m.keep[c] = true;
  }
  if (std::find(m.keep.begin(), m.keep.end(), true) == m.keep.end()) {
    std::string have;
    for (const auto& n : m.names) have += (have.empty() ? "" : ", ") + n;
    if (have.size() > 200) have = have.substr(0, 200) + "...";
    throw Error("none of the dynamic classes [" + listed + "] is in names file " + m.files.names +
                " (" + have + "); set Detector.dynamicClasses to names from that file");
  }

  if (options.input_width > 0 && options.input_height > 0) {
    m.input = {options.input_width, options.input_height};
  } else if (m.files.format == ModelFormat::Darknet) {
    m.input = darknetInputSize(m.files.cfg);
  } else {
    m.input = onnxInputSize(m.files.weights);
    if (m.input.area() == 0)
      throw Error("ONNX model " + m.files.weights + " has no fixed input size; set "
                  "Detector.inputWidth and Detector.inputHeight");
  }

  if (m.files.format == ModelFormat::Darknet) checkDarknetWeights(m.files.cfg, m.files.weights);
  m.setThreads();
  try {
    m.net = m.files.format == ModelFormat::Darknet
                ? cv::dnn::readNetFromDarknet(m.files.cfg, m.files.weights)
                : cv::dnn::readNetFromONNX(m.files.weights);
    if (m.net.empty()) throw cv::Exception(0, "empty network", "", "", 0);
    m.net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
    m.net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
    m.out_names = m.net.getUnconnectedOutLayersNames();
    m.inspectOutputs();
  } catch (const cv::Exception& e) {
    std::string why = e.err.empty() ? e.what() : e.err;
    throw Error("cannot load detection model " + m.modelFile() + " at input " +
                std::to_string(m.input.width) + "x" + std::to_string(m.input.height) + " (" +
                why + "); the file is corrupt, truncated or does not match; re-download it or "
                "point Detector.model / YOLO_SLAM_MODEL at a valid model");
  }
}

YoloDetector::~YoloDetector() = default;

Boxes YoloDetector::detect(const cv::Mat& image) {
  Impl& m = *impl_;
  if (image.empty()) throw Error("YoloDetector::detect: empty image");
  cv::Mat bgr;
  if (image.depth() != CV_8U)
    throw Error("YoloDetector::detect: image must be 8-bit (got depth " +
                std::to_string(image.depth()) + ")");
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  else if (image.channels() == 4) cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  else if (image.channels() == 3) bgr = image;
  else throw Error("YoloDetector::detect: image must have 1, 3 or 4 channels");

  m.setThreads();
  const InputTransform t = InputTransform::make(bgr.size(), m.input, m.opt.letterbox);
  m.net.setInput(m.blob(fitToInput(bgr, m.input, t)));
  std::vector<cv::Mat> outs;
  m.net.forward(outs, m.out_names);

  std::vector<Candidate> cands;
  const float conf = m.opt.conf_threshold;
  switch (m.head) {
    case Head::DarknetYolo:
      for (const auto& o : outs) decodeYoloRows(o, m.input, true, true, m.keep, conf, cands);
      break;
    case Head::OnnxYolo:
      for (const auto& o : outs) decodeYoloRows(o, m.input, false, false, m.keep, conf, cands);
      break;
    case Head::NanoDet:
      for (const auto& l : m.levels)
        decodeNanoDetLevel(outs[l.cls], outs[l.reg], l.stride, m.input, m.keep, conf, cands);
      break;
  }
  return suppressAndMap(cands, conf, m.opt.nms_threshold, t, bgr.size(), m.names);
}

const DetectorOptions& YoloDetector::options() const { return impl_->opt; }
cv::Size YoloDetector::inputSize() const { return impl_->input; }
const std::vector<std::string>& YoloDetector::classNames() const { return impl_->names; }

std::string YoloDetector::description() const {
  return std::string(headName(impl_->head)) + " " + std::to_string(impl_->input.width) + "x" +
         std::to_string(impl_->input.height) + ", " + std::to_string(impl_->names.size()) +
         " classes, " + impl_->modelFile();
}

Boxes mergeOverlapping(Boxes boxes, float iou_threshold) {
  std::stable_sort(boxes.begin(), boxes.end(), [](const Box& a, const Box& b) { return a.score > b.score; });
  Boxes kept;
  // Each kept box's own rectangle before it grew: overlap is tested against it, so a box grown
  // by one merge cannot swallow the person standing beside (chained merges in a crowd made one
  // box of three people, and depth screening keeps one person per box).
  std::vector<cv::Rect2f> seeds;
  for (const Box& b : boxes) {
    auto hit = std::find_if(seeds.begin(), seeds.end(),
                            [&](const cv::Rect2f& s) { return iou(s, b.rect) > iou_threshold; });
    if (hit == seeds.end()) {
      kept.push_back(b);
      seeds.push_back(b.rect);
    } else {
      kept[static_cast<size_t>(hit - seeds.begin())].rect |= b.rect;
    }
  }
  return kept;
}

MultiModelDetector::MultiModelDetector(const DetectorOptions& options) : merge_iou_(options.nms_threshold) {
  models_.push_back(std::make_unique<YoloDetector>(options));
  for (const auto& path : options.extra_models) {
    DetectorOptions one = options;
    one.model = path;
    one.extra_models.clear();
    try {
      models_.push_back(std::make_unique<YoloDetector>(one));
    } catch (const Error& e) {
      throw Error(std::string(e.what()) + " (an entry of Detector.extraModels; set it to \"\" to "
                  "run the main model alone)");
    }
  }
}

Boxes MultiModelDetector::detect(const cv::Mat& bgr) {
  Boxes all;
  for (auto& m : models_) {
    Boxes b = m->detect(bgr);
    all.insert(all.end(), b.begin(), b.end());
  }
  return mergeOverlapping(std::move(all), merge_iou_);
}

std::string MultiModelDetector::description() const {
  std::string d;
  for (const auto& m : models_) d += (d.empty() ? "" : "; ") + m->description();
  return d;
}

std::unique_ptr<Detector> makeDetector(const DetectorOptions& options) {
  if (options.extra_models.empty()) return std::make_unique<YoloDetector>(options);
  return std::make_unique<MultiModelDetector>(options);
}

}  // namespace detection
}  // namespace yolo_slam
