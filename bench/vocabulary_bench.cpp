// vocabulary_bench: load time of the shipped vocabulary and of a synthetic 10^6-word one,
// transform time of 1000 descriptors (k=10, L=6), and retrieval precision@1 on held-out real
// photographs under synthetic changes of viewpoint.
//
//   vocabulary_bench [--vocab FILE] [--warps 3] [--strength 1.0] [--skip-synthetic]
#include "yolo_slam/common/cli.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/vocabulary/keyframe_database.h"
#include "yolo_slam/vocabulary/training_inputs.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <random>
#include <sys/stat.h>
#include <unistd.h>

using namespace yolo_slam;
using namespace yolo_slam::vocabulary;

namespace {

// Held-out real photographs: opencv-doc's examples/data photographs (the simulator's texture
// pool, never used for training) and the real images in ../shared.
std::vector<std::string> heldOut() {
  const std::string doc = "/usr/share/doc/opencv-doc/examples/data/";
  const std::string shared = joinPath(sharedDir(), "data");
  std::vector<std::string> v = {shared + "/images/bus.jpg", shared + "/images/person.jpg",
                                shared + "/images/basketball1.png",
                                shared + "/tum/rgbd_dataset_freiburg3_walking_xyz/rgb/1341846313.592026.png"};
  for (const char* f : {"building.jpg", "home.jpg", "baboon.jpg", "fruits.jpg", "graf1.png", "aero1.jpg",
                        "box_in_scene.png", "messi5.jpg", "leuvenA.jpg", "stuff.jpg", "board.jpg",
                        "butterfly.jpg", "orange.jpg", "apple.jpg", "squirrel_cls.jpg", "starry_night.jpg",
                        "smarties.png", "ela_original.jpg", "rubberwhale1.png", "aloeL.jpg", "left01.jpg",
                        "licenseplate_motion.jpg", "HappyFish.jpg", "pic1.png"})
    v.push_back(doc + f);
  return v;
}

std::shared_ptr<Vocabulary> syntheticTree(int k, int levels, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<uint32_t> parents{0};
  size_t level_begin = 0, level_end = 1;
  for (int l = 0; l < levels; ++l) {
    for (size_t p = level_begin; p < level_end; ++p)
      for (int c = 0; c < k; ++c) parents.push_back(static_cast<uint32_t>(p));
    level_begin = level_end;
    level_end = parents.size();
  }
  std::vector<uint8_t> desc(parents.size() * 32);
  for (size_t i = 0; i < desc.size(); i += 8) {
    const uint64_t r = rng();
    std::memcpy(&desc[i], &r, 8);
  }
  std::vector<double> weights(parents.size());
  for (auto& w : weights) w = std::uniform_real_distribution<double>(0.1, 5.0)(rng);
  return Vocabulary::fromNodes(k, levels, Weighting::TfIdf, Scoring::L1, parents, desc, weights, {},
                               "synthetic");
}

double fileMb(const std::string& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 ? st.st_size / 1e6 : 0.0;
}

Summary timeLoads(const std::string& path, int reps) {
  std::vector<double> ms;
  for (int i = 0; i < reps; ++i) {
    Stopwatch sw;
    auto v = Vocabulary::load(path);
    ms.push_back(sw.ms());
  }
  return summarize(ms);
}

Summary timeTransform(const Vocabulary& v, const cv::Mat& d, int reps) {
  std::vector<double> ms;
  BowVector bow;
  FeatureVector fv;
  for (int i = 0; i < reps; ++i) {
    Stopwatch sw;
    v.transform(d, bow, fv, 4);
    ms.push_back(sw.ms());
  }
  return summarize(ms);
}

int run(int argc, char** argv) {
  std::string vocab_path = joinPath(packageDir(), "vocab/yolo_slam_orb_k10_L4.vocab");
  int warps = 3;
  double strength = 1.0;
  bool synthetic = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--vocab" && i + 1 < argc) vocab_path = argv[++i];
    else if (a == "--warps" && i + 1 < argc) warps = std::atoi(argv[++i]);
    else if (a == "--strength" && i + 1 < argc) strength = std::atof(argv[++i]);
    else if (a == "--skip-synthetic") synthetic = false;
    else throw Error("unknown argument " + a +
                     " (usage: vocabulary_bench [--vocab FILE] [--warps N] [--strength S] [--skip-synthetic])");
  }

  features::OrbExtractor orb{features::OrbOptions{}};
  const auto paths = heldOut();
  std::vector<cv::Mat> images;
  for (const auto& p : paths) {
    cv::Mat g = cv::imread(p, cv::IMREAD_GRAYSCALE);
    if (g.empty()) throw Error(p + ": cannot read held-out image");
    images.push_back(g);
  }
  auto extract = [&](const cv::Mat& g) {
    std::vector<cv::KeyPoint> k;
    cv::Mat d;
    orb.extract(g, k, d);
    return d;
  };
  // 1000 real descriptors for transform timing.
  cv::Mat d1000 = extract(images[4]);
  if (d1000.rows < 1000) throw Error("held-out image gave fewer than 1000 descriptors");
  d1000 = d1000.rowRange(0, 1000).clone();

  // Shipped vocabulary.
  const Summary ls = timeLoads(vocab_path, 7);
  auto voc = Vocabulary::load(vocab_path);
  std::printf("shipped %s: k=%d L=%d words=%zu nodes=%zu size=%.2f MB\n", vocab_path.c_str(),
              voc->branching(), voc->levels(), voc->size(), voc->nodeCount(), fileMb(vocab_path));
  std::printf("  load: median %.2f ms (min %.2f, max %.2f, n=%zu)\n", ls.median, ls.min, ls.max, ls.count);
  const Summary ts = timeTransform(*voc, d1000, 200);
  std::printf("  transform 1000 descriptors (bow + fv): median %.3f ms (min %.3f, p95 %.3f)\n", ts.median, ts.min, ts.p95);

  if (synthetic) {
    Stopwatch sw;
    auto big = syntheticTree(10, 6, 1);
    const std::string tmp = "/tmp/ys_vocab_bench_" + std::to_string(::getpid()) + ".vocab";
    big->save(tmp);
    std::printf("synthetic k=10 L=6: words=%zu nodes=%zu size=%.1f MB (built+saved in %.0f ms)\n",
                big->size(), big->nodeCount(), fileMb(tmp), sw.ms());
    timeLoads(tmp, 1);  // warm the page cache
    const Summary bl = timeLoads(tmp, 5);
    std::printf("  load: median %.1f ms (min %.1f, max %.1f, n=%zu)\n", bl.median, bl.min, bl.max, bl.count);
    const Summary bt = timeTransform(*big, d1000, 200);
    std::printf("  transform 1000 descriptors (bow + fv, levels_up 4): median %.3f ms (min %.3f, p95 %.3f)\n",
                bt.median, bt.min, bt.p95);
    std::remove(tmp.c_str());
  }

  // Retrieval: database = originals, queries = warped copies; precision@1 via KeyFrameDatabase.
  KeyFrameDatabase db;
  std::vector<BowVector> bows;
  for (size_t i = 0; i < images.size(); ++i) {
    BowVector b;
    voc->transform(extract(images[i]), b);
    db.add(static_cast<long>(i), b);
    bows.push_back(b);
  }
  int hits = 0, queries = 0;
  double same_sum = 0, other_sum = 0;
  int other_n = 0;
  for (size_t i = 0; i < images.size(); ++i) {
    for (int w = 0; w < warps; ++w) {
      BowVector q;
      voc->transform(extract(syntheticViewChange(images[i], 1000 * i + w, strength)), q);
      const auto r = db.query(q, 1);
      hits += !r.empty() && r[0].first == static_cast<long>(i);
      ++queries;
      same_sum += Vocabulary::score(q, bows[i]);
    }
    for (size_t j = i + 1; j < images.size(); ++j) {
      other_sum += Vocabulary::score(bows[i], bows[j]);
      ++other_n;
    }
  }
  std::printf("retrieval: %zu held-out images x %d warps (strength %.2f): precision@1 = %.3f (%d/%d); "
              "mean score same place %.3f, unrelated %.3f\n",
              images.size(), warps, strength, static_cast<double>(hits) / queries, hits, queries,
              same_sum / queries, other_sum / other_n);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return yolo_slam::runGuarded(run, argc, argv); }
