// yolo_slam_train_vocab: trains a bag-of-words vocabulary on ORB descriptors of our own
// extractor (features::OrbExtractor, so the words match the descriptors SLAM computes).
//
//   yolo_slam_train_vocab --out FILE [--k 10] [--levels 6] [--max-features 1000]
//                         [--video-step 10] [--max-video-frames 0] [--seed 0]
//                         [--iterations 10] [--weighting tf-idf|tf|idf|binary] [--text] INPUT...
//
// INPUT: image folders, image lists (.txt), videos or single images.
#include "yolo_slam/common/cli.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/progress.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/vocabulary/trainer.h"
#include "yolo_slam/vocabulary/training_inputs.h"

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

using namespace yolo_slam;

namespace {

const char* kUsage =
    "usage: yolo_slam_train_vocab --out FILE [--k 10] [--levels 6] [--max-features 1000]\n"
    "         [--video-step 10] [--max-video-frames 0] [--seed 0] [--iterations 10]\n"
    "         [--weighting tf-idf|tf|idf|binary] [--text] INPUT...\n"
    "  INPUT: image folder, image list (.txt, one path per line), video or image\n"
    "  --text writes ORB-SLAM2's ORBvoc.txt format instead of the binary format\n";

int parseInt(const std::string& flag, const std::string& v, int lo, int hi) {
  char* end = nullptr;
  const long x = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || x < lo || x > hi)
    throw Error(flag + ": expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi) +
                ", got '" + v + "'");
  return static_cast<int>(x);
}

vocabulary::Weighting parseWeighting(const std::string& v) {
  if (v == "tf-idf") return vocabulary::Weighting::TfIdf;
  if (v == "tf") return vocabulary::Weighting::Tf;
  if (v == "idf") return vocabulary::Weighting::Idf;
  if (v == "binary") return vocabulary::Weighting::Binary;
  throw Error("--weighting: expected tf-idf, tf, idf or binary, got '" + v + "'");
}

struct Args {
  std::string out;
  vocabulary::TrainerOptions trainer;
  vocabulary::InputOptions inputs_options;
  features::OrbOptions orb;
  bool text = false;
  bool help = false;
  std::vector<std::string> inputs;
};

Args parseArgs(int argc, char** argv) {
  Args args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw Error(a + ": missing value");
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      args.help = true;
      return args;
    } else if (a == "--out") args.out = value();
    else if (a == "--k") args.trainer.k = parseInt(a, value(), 2, 1000);
    else if (a == "--levels") args.trainer.levels = parseInt(a, value(), 1, 12);
    else if (a == "--max-features") args.orb.n_features = parseInt(a, value(), 10, 100000);
    else if (a == "--video-step") args.inputs_options.video_step = parseInt(a, value(), 1, 1000000);
    else if (a == "--max-video-frames") args.inputs_options.max_video_frames = parseInt(a, value(), 0, 100000000);
    else if (a == "--seed") args.trainer.seed = static_cast<uint64_t>(parseInt(a, value(), 0, 2147483647));
    else if (a == "--iterations") args.trainer.max_iterations = parseInt(a, value(), 1, 1000);
    else if (a == "--weighting") args.trainer.weighting = parseWeighting(value());
    else if (a == "--text") args.text = true;
    else if (!a.empty() && a[0] == '-') throw Error("unknown option " + a + " (see --help)");
    else args.inputs.push_back(a);
  }
  if (args.out.empty()) throw Error("--out FILE is required (see --help)");
  if (args.inputs.empty()) throw Error("no INPUT given: pass image folders, lists or videos (see --help)");
  return args;
}

// ORB descriptors of every image, with a progress bar.
std::vector<cv::Mat> extractDescriptors(const std::vector<cv::Mat>& grays, const features::OrbOptions& orb) {
  features::OrbExtractor extractor(orb);
  std::vector<cv::Mat> descriptors(grays.size());
  size_t n_desc = 0;
  Stopwatch sw;
  ProgressBar bar("extract", grays.size());
  for (size_t i = 0; i < grays.size(); ++i) {
    std::vector<cv::KeyPoint> kps;
    extractor.extract(grays[i], kps, descriptors[i]);
    n_desc += static_cast<size_t>(descriptors[i].rows);
    bar.update(i + 1);
  }
  bar.finish();
  std::printf("extracted %zu descriptors (max %d per image) in %.1f s\n", n_desc, orb.n_features,
              sw.ms() / 1000.0);
  return descriptors;
}

void printReport(const vocabulary::TrainerOptions& topt, const vocabulary::TrainingReport& rep, double total_s) {
  std::printf("k=%d L=%d weighting=%s seed=%llu\n", topt.k, topt.levels,
              vocabulary::toString(topt.weighting).c_str(), static_cast<unsigned long long>(topt.seed));
  std::printf("images: %zu  descriptors: %zu\n", rep.images, rep.descriptors);
  std::printf("words: %zu of capacity k^L = %.0f (%.1f%%)  nodes: %zu\n", rep.words, rep.capacity,
              100.0 * rep.words / rep.capacity, rep.nodes);
  std::printf("leaf occupancy: %zu words (%.1f%%) reached by training descriptors, %zu (%.1f%%) in >= 2 images;"
              " descriptors per word mean %.1f median %.1f\n",
              rep.words_hit, 100.0 * rep.words_hit / rep.words, rep.words_in_two_images,
              100.0 * rep.words_in_two_images / rep.words, rep.mean_descriptors_per_word,
              rep.median_descriptors_per_word);
  std::printf("timing: clustering %.1f s, weights %.1f s, total %.1f s\n", rep.cluster_seconds,
              rep.weight_seconds, total_s);
}

int run(int argc, char** argv) {
  const Args args = parseArgs(argc, argv);
  if (args.help) {
    std::cout << kUsage;
    return 0;
  }
  Stopwatch total;
  const auto items = vocabulary::expandInputs(args.inputs, args.inputs_options);
  std::cout << "inputs: " << items.size() << " images/frames from " << args.inputs.size() << " inputs\n";
  const std::vector<cv::Mat> descriptors = extractDescriptors(vocabulary::loadGrayImages(items), args.orb);

  vocabulary::TrainingReport rep;
  std::shared_ptr<vocabulary::Vocabulary> voc;
  {
    ProgressBar bar("cluster", 1000);
    voc = vocabulary::trainVocabulary(descriptors, args.trainer, &rep, [&](size_t done, size_t tot) {
      bar.update(tot ? done * 1000 / tot : 0);
    });
    bar.finish();
  }
  if (args.text) voc->saveText(args.out);
  else voc->save(args.out);
  printReport(args.trainer, rep, total.ms() / 1000.0);
  std::printf("wrote %s\n", args.out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return yolo_slam::runGuarded(run, argc, argv); }
