// ORB extraction time on a real 640x480 TUM frame (fr3_walking_xyz, from the shared data).
// Usage: features_bench [image] [runs]   (default: the shared TUM frame, 50 runs)
// Prints median/mean/p95 ms of OrbExtractor::extract and of buildFeatureFrame (with depth).
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/features/frame_builder.h"
#include "yolo_slam/features/orb_extractor.h"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <cstdlib>
#include <string>

using namespace yolo_slam;

int main(int argc, char** argv) {
  try {
    const std::string seq =
        joinPath(sharedDir(), "data/tum/rgbd_dataset_freiburg3_walking_xyz");
    std::string path = argc > 1 ? argv[1] : joinPath(seq, "rgb/1341846313.592026.png");
    const int runs = argc > 2 ? std::atoi(argv[2]) : 50;
    if (runs <= 0) throw Error("features_bench: runs must be a positive integer");
    cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
    if (bgr.empty()) throw Error(path + ": cannot read image; pass an existing image file");
    cv::Mat depth;
    const std::string depth_path = joinPath(seq, "depth/1341846313.592088.png");
    cv::Mat raw = cv::imread(depth_path, cv::IMREAD_ANYDEPTH);
    if (!raw.empty() && raw.size() == bgr.size()) raw.convertTo(depth, CV_32F, 1.0 / 5000.0);

    features::OrbExtractor orb(features::OrbOptions{});
    CameraModel cam;
    cv::Mat gray = features::toGray(bgr, cam.rgb_order);

    std::vector<cv::KeyPoint> kps;
    cv::Mat desc;
    orb.extract(gray, kps, desc);  // warm-up (caches, pattern table)
    std::vector<double> t_extract, t_frame;
    for (int i = 0; i < runs; ++i) {
      Stopwatch sw;
      orb.extract(gray, kps, desc);
      t_extract.push_back(sw.ms());
    }
    size_t with_depth = 0;
    for (int i = 0; i < runs; ++i) {
      Stopwatch sw;
      features::FeatureFrame f = features::buildFeatureFrame(orb, cam, bgr, depth, 0.0);
      t_frame.push_back(sw.ms());
      with_depth = 0;
      for (float d : f.depth) with_depth += d > 0 ? 1 : 0;
    }
    Summary se = summarize(t_extract), sf = summarize(t_frame);
    std::printf("image %s (%dx%d), %d runs\n", path.c_str(), gray.cols, gray.rows, runs);
    std::printf("keypoints %zu (n_features %d), with depth %zu\n", kps.size(),
                orb.options().n_features, with_depth);
    std::printf("extract           median %.3f ms  mean %.3f  p95 %.3f  min %.3f\n", se.median,
                se.mean, se.p95, se.min);
    std::printf("buildFeatureFrame median %.3f ms  mean %.3f  p95 %.3f  min %.3f\n", sf.median,
                sf.mean, sf.p95, sf.min);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
