// yolo_slam_detect: runs the person detector on images and prints the boxes (text or JSON),
// optionally drawing them to PNG files.
#include "yolo_slam/common/cli.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/json.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/detection/draw.h"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

using namespace yolo_slam;

namespace {

const char* kUsage =
    "usage: yolo_slam_detect [--model DIR_OR_CFG_OR_ONNX] [--extra-model M ... | --single-model]\n"
    "                        [--json] [--draw OUT.png | --draw-dir DIR] [--conf T] [--nms T]\n"
    "                        [--size WxH] [--no-letterbox] [--threads N] [--classes a,b,...] IMAGE...\n"
    "Prints the boxes of the dynamic classes (default: person, body) found in each image by the\n"
    "same detector the pipeline runs (main model plus extra models, boxes merged).\n"
    "  --model      main model folder, .cfg or .onnx (default: $YOLO_SLAM_MODEL, else\n"
    "               <shared>/models/mnv2-yolov3-nano-voc)\n"
    "  --extra-model  a model run beside the main one (repeatable; replaces the default extra\n"
    "               model <shared>/models/yolo-fastest-1.1-body, as Detector.extraModels)\n"
    "  --single-model  the main model alone (Detector.extraModels: \"\")\n"
    "  --json       print [{\"image\":..,\"boxes\":[{\"class\",\"score\",\"x1\",\"y1\",\"x2\",\"y2\"}]}]\n"
    "  --draw       write the boxes drawn on the image to OUT.png (one image only)\n"
    "  --draw-dir   write <DIR>/<image name>.png for every image\n"
    "  --conf/--nms confidence (0.3) and NMS IoU (0.45) thresholds\n"
    "  --size       network input size, multiple of 32 (default: the model's own)\n"
    "  --no-letterbox  stretch the image to the input size instead of letterboxing it (the\n"
    "               default keeps the aspect ratio, as Detector.letterbox: 1)\n";

std::string baseName(const std::string& path) {
  size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  size_t dot = name.find_last_of('.');
  return dot == std::string::npos ? name : name.substr(0, dot);
}

float parseFloat(const std::string& flag, const std::string& v) {
  char* end = nullptr;
  float f = std::strtof(v.c_str(), &end);
  if (v.empty() || *end) throw Error(flag + " needs a number, got '" + v + "'");
  return f;
}

struct DetectArgs {
  detection::DetectorOptions opt;
  bool json = false, extra_given = false, single = false, help = false;
  std::string draw, draw_dir;
  std::vector<std::string> images;
};

std::vector<std::string> splitCommas(const std::string& v) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= v.size()) {
    const size_t comma = v.find(',', start);
    const std::string c = v.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!c.empty()) out.push_back(c);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// One option (with its value, read through `value`); false if `a` is not an option.
bool parseOption(const std::string& a, const std::function<std::string()>& value, DetectArgs& d) {
  detection::DetectorOptions& opt = d.opt;
  if (a == "-h" || a == "--help") {
    d.help = true;
  } else if (a == "--model") {
    opt.model = value();
  } else if (a == "--extra-model") {
    if (d.single) throw Error("--single-model and --extra-model exclude each other");
    if (!d.extra_given) opt.extra_models.clear();
    d.extra_given = true;
    opt.extra_models.push_back(value());
  } else if (a == "--single-model") {
    if (d.extra_given) throw Error("--single-model and --extra-model exclude each other");
    d.single = true;
    opt.extra_models.clear();
  } else if (a == "--json") {
    d.json = true;
  } else if (a == "--draw") {
    d.draw = value();
  } else if (a == "--draw-dir") {
    d.draw_dir = value();
  } else if (a == "--conf") {
    opt.conf_threshold = parseFloat(a, value());
  } else if (a == "--nms") {
    opt.nms_threshold = parseFloat(a, value());
  } else if (a == "--threads") {
    const float t = parseFloat(a, value());
    constexpr int kMaxThreads = detection::DetectorOptions::kMaxThreads;
    if (!(t >= 1 && t <= kMaxThreads)) throw Error("--threads must be in [1, " + std::to_string(kMaxThreads) + "]");
    opt.threads = int(t);
  } else if (a == "--no-letterbox") {
    opt.letterbox = false;
  } else if (a == "--size") {
    const std::string v = value();
    if (std::sscanf(v.c_str(), "%dx%d", &opt.input_width, &opt.input_height) != 2)
      throw Error("--size needs WxH, e.g. 416x416, got '" + v + "'");
  } else if (a == "--classes") {
    opt.dynamic_classes = splitCommas(value());
  } else {
    return false;
  }
  return true;
}

DetectArgs parseArgs(int argc, char** argv) {
  DetectArgs d;
  for (int i = 1; i < argc && !d.help; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw Error(a + " needs a value (see --help)");
      return argv[++i];
    };
    if (parseOption(a, value, d)) continue;
    if (!a.empty() && a[0] == '-') throw Error("unknown option " + a + " (see --help)");
    d.images.push_back(a);
  }
  return d;
}

void checkArgs(const DetectArgs& d) {
  const detection::DetectorOptions& opt = d.opt;
  if (!d.draw.empty() && d.images.size() != 1)
    throw Error("--draw takes one image; use --draw-dir DIR for several");
  if (!(opt.conf_threshold > 0 && opt.conf_threshold < 1)) throw Error("--conf must be in (0,1)");
  if (!(opt.nms_threshold > 0 && opt.nms_threshold <= 1)) throw Error("--nms must be in (0,1]");
  if ((opt.input_width % 32) || (opt.input_height % 32) || opt.input_width < 0 || opt.input_height < 0)
    throw Error("--size must be positive multiples of 32");
  if (!d.draw_dir.empty() && !dirExists(d.draw_dir))
    throw Error("--draw-dir " + d.draw_dir + " is not an existing folder; create it first");
}

int run(int argc, char** argv) {
  const DetectArgs args = parseArgs(argc, argv);
  if (args.help) {
    std::cout << kUsage;
    return 0;
  }
  if (args.images.empty()) {
    std::cerr << kUsage;
    return 1;
  }
  checkArgs(args);
  const detection::DetectorOptions& opt = args.opt;
  const bool json = args.json;
  const std::string& draw = args.draw;
  const std::string& draw_dir = args.draw_dir;
  const std::vector<std::string>& images = args.images;

  std::unique_ptr<detection::Detector> detector = detection::makeDetector(opt);
  if (!json) std::cout << "# model: " << detector->description() << "\n";
  Json results = Json::array();
  for (size_t i = 0; i < images.size(); ++i) {
    cv::Mat img = cv::imread(images[i], cv::IMREAD_COLOR);
    if (img.empty()) throw Error("cannot read image " + images[i] + "; check the path and format");
    detection::Boxes boxes = detector->detect(img);
    if (json) {
      results.push_back({{"image", images[i]}, {"boxes", detection::boxesJson(boxes)}});
    } else {
      std::cout << images[i] << ": " << boxes.size() << " box(es)\n";
      for (const auto& b : boxes) {
        char line[256];
        std::snprintf(line, sizeof(line), "  %s %.3f  x1=%.1f y1=%.1f x2=%.1f y2=%.1f\n",
                      b.label.c_str(), b.score, b.rect.x, b.rect.y, b.rect.x + b.rect.width,
                      b.rect.y + b.rect.height);
        std::cout << line;
      }
    }
    std::string out = !draw.empty() ? draw
                      : !draw_dir.empty() ? joinPath(draw_dir, baseName(images[i]) + ".png")
                                          : "";
    if (!out.empty()) {
      detection::drawBoxes(img, boxes);
      bool ok = false;
      try {
        ok = cv::imwrite(out, img);
      } catch (const cv::Exception&) {
        ok = false;
      }
      if (!ok) throw Error("cannot write " + out + "; check the folder exists and the name ends in .png");
    }
  }
  if (json) std::cout << results.dump() << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return yolo_slam::runGuarded(run, argc, argv); }
