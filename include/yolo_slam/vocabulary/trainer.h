#pragma once
// Training a vocabulary: hierarchical k-majority clustering of ORB descriptors (k-means++
// seeding with Hamming distance, centroids by bitwise majority vote), then IDF word weights
// from how many training images contain each word. Deterministic for a given seed.
#include "yolo_slam/vocabulary/vocabulary.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace yolo_slam {
namespace vocabulary {

struct TrainerOptions {
  int k = 10;                 // branching factor
  int levels = 6;             // depth L (capacity k^L words)
  Weighting weighting = Weighting::TfIdf;
  int max_iterations = 10;    // k-majority iterations per node (stops earlier when stable)
  uint64_t seed = 0;
};

struct TrainingReport {
  size_t images = 0, descriptors = 0;
  size_t nodes = 0, words = 0;
  double capacity = 0;              // k^L
  size_t words_hit = 0;             // words reached by at least one training descriptor
  size_t words_in_two_images = 0;   // words seen in >= 2 training images (carry idf > 0 info)
  double mean_descriptors_per_word = 0, median_descriptors_per_word = 0;
  double cluster_seconds = 0, weight_seconds = 0;
};

// `images` holds one N_i x 32 CV_8U descriptor matrix per training image (the image split is
// what IDF counts). Throws yolo_slam::Error for bad options or when there are fewer than k
// descriptors in total. `progress(done, total)` is called as clustering advances.
std::shared_ptr<Vocabulary> trainVocabulary(const std::vector<cv::Mat>& images,
                                            const TrainerOptions& options,
                                            TrainingReport* report = nullptr,
                                            const std::function<void(size_t, size_t)>& progress = {});

}  // namespace vocabulary
}  // namespace yolo_slam
