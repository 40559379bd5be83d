// detection_bench: ms per 640x480 frame (median of N after a warm-up) for each shared model at
// its native input size, with 1 and 2 threads. Usage: detection_bench [--frames N] [--json]
// [MODEL...]; default models: the five in <shared>/models, then the default detector (main
// model plus Detector.extraModels, as the pipeline runs it).
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/detection/detector.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

using namespace yolo_slam;

int main(int argc, char** argv) {
  try {
    int frames = 50;
    bool json = false;
    std::vector<std::string> models;
    for (int i = 1; i < argc; ++i) {
      std::string a = argv[i];
      if (a == "--frames" && i + 1 < argc) {
        frames = std::atoi(argv[++i]);
        if (frames < 1) throw Error("--frames must be at least 1");
      } else if (a == "--json") {
        json = true;
      } else if (!a.empty() && a[0] == '-') {
        throw Error("unknown option " + a + "; usage: detection_bench [--frames N] [--json] [MODEL...]");
      } else {
        models.push_back(a);
      }
    }
    const bool default_models = models.empty();
    if (default_models)
      for (const char* m : {"mnv2-yolov3-nano-voc", "mnv2-yolov3-nano-coco", "yolo-fastest-xl-voc",
                            "yolo-fastest-1.1-body", "nanodet-m/nanodet.onnx", "nanodet-m/nanodet_m.onnx"})
        models.push_back(joinPath(sharedDir(), std::string("models/") + m));

    // A real 640x480 frame (TUM fr3 walking_xyz, two people).
    const std::string frame_path = joinPath(
        sharedDir(), "data/tum/rgbd_dataset_freiburg3_walking_xyz/rgb/1341846313.592026.png");
    cv::Mat frame = cv::imread(frame_path, cv::IMREAD_COLOR);
    if (frame.empty()) throw Error("cannot read " + frame_path + "; set YOLO_SLAM_SHARED");
    if (frame.size() != cv::Size(640, 480)) cv::resize(frame, frame, cv::Size(640, 480));

    if (json) std::cout << "[";
    bool first = true;
    auto measure = [&](detection::Detector& det, const std::string& name, const std::string& input,
                       int threads) {
      for (int i = 0; i < 3; ++i) det.detect(frame);  // warm-up
      std::vector<double> ms;
      size_t boxes = 0;
      for (int i = 0; i < frames; ++i) {
        Stopwatch sw;
        boxes = det.detect(frame).size();
        ms.push_back(sw.ms());
      }
      Summary s = summarize(ms);
      if (json) {
        std::printf("%s{\"model\":\"%s\",\"input\":\"%s\",\"threads\":%d,\"frames\":%d,"
                    "\"median_ms\":%.2f,\"p95_ms\":%.2f,\"boxes\":%zu}",
                    first ? "" : ",\n ", name.c_str(), input.c_str(), threads, frames, s.median, s.p95,
                    boxes);
      } else {
        std::printf("%-60s %s threads=%d median=%.2f ms p95=%.2f ms boxes=%zu\n", name.c_str(),
                    input.c_str(), threads, s.median, s.p95, boxes);
      }
      std::fflush(stdout);
      first = false;
    };
    for (const auto& model : models) {
      for (int threads : {1, 2}) {
        detection::DetectorOptions opt;
        opt.model = model;
        opt.threads = threads;
        opt.extra_models.clear();
        detection::YoloDetector det(opt);
        const cv::Size in = det.inputSize();
        measure(det, model, std::to_string(in.width) + "x" + std::to_string(in.height), threads);
      }
    }
    if (default_models) {
      // What the pipeline runs by default: the main model plus Detector.extraModels, merged.
      for (int threads : {1, 2}) {
        detection::DetectorOptions opt;
        opt.threads = threads;
        std::unique_ptr<detection::Detector> det = detection::makeDetector(opt);
        measure(*det, "default detector (main + extra models)", "native", threads);
      }
    }
    if (json) std::cout << "]\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
