// Benchmark of the synthetic sequence generator: per preset, generation speed (frames written
// per second, wall clock and CPU) and the default detector's recall on the people the issue
// counts (visible fraction > 0.5, box at least 80 px tall, matched at IoU >= 0.5).
//   sim_bench [--frames N] [--every K] [--no-detector] [PRESET ...]
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/sim/generator.h"

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

using namespace yolo_slam;

static double iou(const cv::Rect2f& a, const cv::Rect2f& b) {
  float inter = (a & b).area();
  float uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

int main(int argc, char** argv) {
  try {
    int frames = 150, every = 3;
    bool detect = true;
    std::vector<std::string> names;
    for (int i = 1; i < argc; ++i) {
      std::string a = argv[i];
      if (a == "--frames" && i + 1 < argc) frames = std::atoi(argv[++i]);
      else if (a == "--every" && i + 1 < argc) every = std::max(1, std::atoi(argv[++i]));
      else if (a == "--no-detector") detect = false;
      else if (a == "-h" || a == "--help") {
        std::printf("usage: sim_bench [--frames N] [--every K] [--no-detector] [PRESET ...]\n");
        return 0;
      } else names.push_back(a);
    }
    if (names.empty())
      for (const auto& p : sim::presets()) names.push_back(p.name);
    std::unique_ptr<detection::Detector> det;
    if (detect) det = detection::makeDetector(detection::DetectorOptions());
    std::printf("{\"frames\": %d, \"presets\": [\n", frames);
    for (size_t k = 0; k < names.size(); ++k) {
      sim::SynthOptions o;
      o.preset = names[k];
      o.frames = frames;
      Stopwatch load;
      sim::SequenceGenerator gen(o);
      double load_ms = load.ms();
      std::string dir = (std::filesystem::temp_directory_path() / ("sim_bench_" + names[k])).string();
      std::clock_t c0 = std::clock();
      double secs = gen.generate(dir);
      double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
      std::filesystem::remove_all(dir);
      // Recall of the default detector on every `every`-th frame.
      int counted = 0, found = 0;
      if (det)
        for (size_t i = 0; i < gen.size(); i += every) {
          sim::SynthFrame f = gen.frame(i);
          detection::Boxes boxes;
          bool detected = false;
          for (const auto& ob : f.objects) {
            if (ob.cls != "person" || ob.visible_fraction <= 0.5 || ob.box.height < 80) continue;
            if (!detected) boxes = det->detect(f.bgr), detected = true;
            ++counted;
            for (const auto& b : boxes)
              if (iou(b.rect, cv::Rect2f(ob.box)) >= 0.5) {
                ++found;
                break;
              }
          }
        }
      std::printf("  {\"preset\": \"%s\", \"frames\": %zu, \"load_s\": %.2f, \"generate_s\": %.2f, "
                  "\"fps_wall\": %.1f, \"cpu_ms_per_frame\": %.1f, \"threads\": %d, "
                  "\"people_counted\": %d, \"people_found\": %d, \"recall\": %s}%s\n",
                  names[k].c_str(), gen.size(), load_ms / 1000, secs, gen.size() / secs,
                  1000 * cpu / gen.size(), o.threads, counted, found,
                  counted ? std::to_string((double)found / counted).c_str() : "null",
                  k + 1 < names.size() ? "," : "");
      std::fflush(stdout);
    }
    std::printf("]}\n");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
