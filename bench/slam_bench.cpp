// slam_bench: per-frame cost of the tracking thread (extraction + screening + tracking) on a
// TUM folder, as wall time and as the calling thread's CPU time (robust when the machine is
// shared), plus ATE when the folder has ground truth.
//   slam_bench --sequence DIR --config YAML [--max-frames N] [--features N] [--dynamic-mode M]
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/eval/ate.h"
#include "yolo_slam/io/tum_sequence.h"
#include "yolo_slam/slam/system.h"

#include "gt_boxes.h"

#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

using namespace yolo_slam;

int main(int argc, char** argv) {
  try {
    std::string seq_dir, config, mode = "off";
    long max_frames = -1;
    int n_features = 0;
    std::vector<std::string> overrides;
    bool boxes_from_gt = false;
    for (int i = 1; i < argc; ++i) {
      std::string s = argv[i];
      auto val = [&]() -> std::string {
        if (i + 1 >= argc) throw Error("missing value after " + s);
        return argv[++i];
      };
      if (s == "--sequence") seq_dir = val();
      else if (s == "--config") config = val();
      else if (s == "--max-frames") max_frames = std::atol(val().c_str());
      else if (s == "--features") n_features = std::atoi(val().c_str());
      else if (s == "--dynamic-mode") mode = val();
      else if (s == "--set") overrides.push_back(val());
      else if (s == "--boxes-from-gt") boxes_from_gt = true;
      else throw Error("unknown option '" + s + "'");
    }
    if (seq_dir.empty() || config.empty())
      throw Error("usage: slam_bench --sequence DIR --config YAML [--max-frames N] [--features N] [--dynamic-mode M] "
                  "[--set KEY=VALUE ...] [--boxes-from-gt]");
    Config cfg = Config::fromFile(config);
    for (const auto& o : overrides) cfg.setFromAssignment(o);
    CameraModel cam = CameraModel::load(cfg);
    slam::SystemOptions opt = slam::SystemOptions::load(cfg);
    opt.screening.mode = screening::parseDynamicMode(mode);
    if (n_features > 0) opt.orb.n_features = n_features;
    io::TumSequence seq = io::TumSequence::open(seq_dir);
    size_t n = seq.size();
    if (max_frames > 0) n = std::min(n, static_cast<size_t>(max_frames));
    // Person boxes from a synthetic sequence's ground truth (no detector time in the frame).
    const std::map<long, detection::Boxes> gt_boxes =
        boxes_from_gt ? bench::readPersonBoxes(seq_dir + "/boxes.txt") : std::map<long, detection::Boxes>{};
    slam::System sys(cam, opt, nullptr);
    std::vector<double> wall, cpu;
    for (size_t i = 0; i < n; ++i) {
      cv::Mat bgr = seq.loadRgb(i);
      cv::Mat depth = seq.loadDepth(i, cam.depth_map_factor);
      Stopwatch sw;
      const double c0 = threadCpuMs();
      const auto b = gt_boxes.find(bench::stampKey(seq.frames()[i].rgb_stamp));
      sys.trackRgbd(bgr, depth, seq.frames()[i].rgb_stamp, b == gt_boxes.end() ? detection::Boxes{} : b->second);
      cpu.push_back(threadCpuMs() - c0);
      wall.push_back(sw.ms());
    }
    sys.waitForLocalMapping();
    slam::SystemStats st = sys.stats();
    Summary w = summarize(wall), c = summarize(cpu);
    std::printf("frames %zu tracked %zu lost %zu keyframes %zu features %d\n", st.frames, st.tracked, st.lost,
                st.keyframes, opt.orb.n_features);
    std::printf("extraction+screening+tracking wall: median %.2f ms mean %.2f p95 %.2f\n", w.median, w.mean, w.p95);
    std::printf("extraction+screening+tracking cpu:  median %.2f ms mean %.2f p95 %.2f\n", c.median, c.mean, c.p95);
    Summary e = summarize(st.extraction_ms), t = summarize(st.tracking_ms), lm = summarize(st.local_mapping_ms);
    std::printf("wall per stage (median): extraction %.2f ms, tracking %.2f ms, local mapping %.1f ms/keyframe\n",
                e.median, t.median, lm.median);
    if (const mapping::DenseMapper* dense = sys.denseMap()) {
      const mapping::DenseMapStats d = dense->stats();
      std::printf("dense map: %zu keyframes integrated, %zu dropped, integration median %.1f ms wall %.1f ms cpu\n",
                  d.keyframes, d.dropped, summarize(d.integration_ms).median, summarize(d.integration_cpu_ms).median);
    }
    if (seq.hasGroundTruth()) {
      Trajectory traj = sys.cameraTrajectory();
      if (traj.size() >= 2) std::printf("ATE RMSE %.4f m\n", eval::computeAte(seq.groundTruth(), traj).stats.rmse);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
