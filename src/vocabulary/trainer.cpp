#include "yolo_slam/vocabulary/trainer.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <deque>
#include <random>

namespace yolo_slam {
namespace vocabulary {
namespace {

using Desc = std::array<uint64_t, 4>;

inline int hamming(const Desc& a, const Desc& b) {
  return __builtin_popcountll(a[0] ^ b[0]) + __builtin_popcountll(a[1] ^ b[1]) +
         __builtin_popcountll(a[2] ^ b[2]) + __builtin_popcountll(a[3] ^ b[3]);
}

// Bitwise majority of the members (ties give 1, as DBoW2's ORB mean does).
Desc majority(const std::vector<Desc>& data, const std::vector<uint32_t>& members) {
  uint32_t count[256] = {0};
  for (uint32_t m : members) {
    const Desc& d = data[m];
    for (int w = 0; w < 4; ++w) {
      const uint64_t x = d[w];
      uint32_t* c = count + 64 * w;
      for (int b = 0; b < 64; ++b) c[b] += static_cast<uint32_t>((x >> b) & 1u);
    }
  }
  Desc out{0, 0, 0, 0};
  const size_t n = members.size();
  for (int i = 0; i < 256; ++i)
    if (2 * static_cast<size_t>(count[i]) >= n) out[i / 64] |= uint64_t(1) << (i % 64);
  return out;
}

struct Work {
  uint32_t node;
  int level;
  std::vector<uint32_t> members;
};

// k-means++ seeding: the first centre drawn uniformly, each next one with probability
// proportional to the squared distance to the nearest centre so far.
void seedCentres(const std::vector<Desc>& data, const std::vector<uint32_t>& members, int k,
                 std::mt19937_64& rng, std::vector<Desc>& centres) {
  const size_t n = members.size();
  centres.clear();
  centres.push_back(data[members[std::uniform_int_distribution<size_t>(0, n - 1)(rng)]]);
  std::vector<double> d2(n);
  for (size_t i = 0; i < n; ++i) {
    const double d = hamming(data[members[i]], centres[0]);
    d2[i] = d * d;
  }
  while (static_cast<int>(centres.size()) < k) {
    double total = 0;
    for (double v : d2) total += v;
    if (total <= 0) break;  // all remaining descriptors coincide with a centre
    double r = std::uniform_real_distribution<double>(0.0, total)(rng);
    size_t pick = n - 1;
    for (size_t i = 0; i < n; ++i) {
      r -= d2[i];
      if (r < 0) {
        pick = i;
        break;
      }
    }
    centres.push_back(data[members[pick]]);
    for (size_t i = 0; i < n; ++i) {
      const double d = hamming(data[members[i]], centres.back());
      d2[i] = std::min(d2[i], d * d);
    }
  }
}

// The nearest centre (first of equals) of a descriptor.
uint32_t nearestCentre(const Desc& d, const std::vector<Desc>& centres) {
  uint32_t best = 0;
  int best_d = hamming(d, centres[0]);
  for (size_t c = 1; c < centres.size(); ++c) {
    const int dc = hamming(d, centres[c]);
    if (dc < best_d) {
      best_d = dc;
      best = static_cast<uint32_t>(c);
    }
  }
  return best;
}

// Removes the clusters left without members, keeping the others' order.
void dropEmptyClusters(std::vector<Desc>& centres, std::vector<std::vector<uint32_t>>& groups) {
  size_t out = 0;
  for (size_t c = 0; c < centres.size(); ++c) {
    if (groups[c].empty()) continue;
    if (out != c) {
      centres[out] = centres[c];
      groups[out] = std::move(groups[c]);
    }
    ++out;
  }
  centres.resize(out);
  groups.resize(out);
}

// k-majority on one node's descriptors; returns the non-empty clusters' centres and members.
void cluster(const std::vector<Desc>& data, const std::vector<uint32_t>& members, int k,
             int max_iterations, std::mt19937_64& rng, std::vector<Desc>& centres,
             std::vector<std::vector<uint32_t>>& groups) {
  const size_t n = members.size();
  seedCentres(data, members, k, rng, centres);
  std::vector<uint32_t> assign(n, 0xffffffffu);
  for (int it = 0; it < std::max(1, max_iterations); ++it) {
    bool changed = false;
    for (size_t i = 0; i < n; ++i) {
      const uint32_t best = nearestCentre(data[members[i]], centres);
      if (assign[i] != best) {
        assign[i] = best;
        changed = true;
      }
    }
    groups.assign(centres.size(), {});
    for (size_t i = 0; i < n; ++i) groups[assign[i]].push_back(members[i]);
    if (!changed && it > 0) break;
    for (size_t c = 0; c < centres.size(); ++c)
      if (!groups[c].empty()) centres[c] = majority(data, groups[c]);
  }
  dropEmptyClusters(centres, groups);
}

uint64_t mix(uint64_t x) {  // splitmix64 finaliser: per-node seeds from (seed, node id)
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Every training descriptor, the image it came from, and how many images gave any.
struct TrainingSet {
  std::vector<Desc> data;
  std::vector<uint32_t> image_of;
  size_t n_images = 0;
};

TrainingSet gatherDescriptors(const std::vector<cv::Mat>& images, int k) {
  TrainingSet t;
  for (size_t i = 0; i < images.size(); ++i) {
    const cv::Mat& m = images[i];
    if (m.empty()) continue;
    if (m.type() != CV_8UC1 || m.cols != kDescriptorBytes)
      throw Error("vocabulary training: image " + std::to_string(i) +
                  " descriptors must be N x 32 CV_8U (ORB)");
    ++t.n_images;
    for (int r = 0; r < m.rows; ++r) {
      Desc d;
      std::memcpy(d.data(), m.ptr<uint8_t>(r), kDescriptorBytes);
      t.data.push_back(d);
      t.image_of.push_back(static_cast<uint32_t>(i));
    }
  }
  if (t.data.size() < static_cast<size_t>(k))
    throw Error("vocabulary training: only " + std::to_string(t.data.size()) +
                " descriptors, need at least k=" + std::to_string(k) + "; add more images");
  return t;
}

// The tree's nodes: parent and descriptor per node id, node 0 the root.
struct Nodes {
  std::vector<uint32_t> parents{0};
  std::vector<Desc> desc{Desc{0, 0, 0, 0}};
};

// Hierarchical k-majority, breadth-first, so node ids are assigned level by level with each
// node's children contiguous.
Nodes growTree(const std::vector<Desc>& data, const TrainerOptions& opt,
               const std::function<void(size_t, size_t)>& progress) {
  Nodes nodes;
  const size_t total = data.size() * static_cast<size_t>(opt.levels);
  size_t done = 0;
  std::deque<Work> queue;
  {
    Work root{0, 0, std::vector<uint32_t>(data.size())};
    for (size_t i = 0; i < data.size(); ++i) root.members[i] = static_cast<uint32_t>(i);
    queue.push_back(std::move(root));
  }
  std::vector<Desc> centres;
  std::vector<std::vector<uint32_t>> groups;
  while (!queue.empty()) {
    Work w = std::move(queue.front());
    queue.pop_front();
    const size_t remaining_levels = static_cast<size_t>(opt.levels - w.level);
    if (w.members.size() <= static_cast<size_t>(opt.k)) {
      // Too few to cluster: each descriptor becomes a leaf (DBoW2 does the same).
      for (uint32_t m : w.members) {
        nodes.parents.push_back(w.node);
        nodes.desc.push_back(data[m]);
      }
      done += w.members.size() * remaining_levels;
    } else {
      std::mt19937_64 rng(mix(opt.seed ^ mix(w.node)));
      cluster(data, w.members, opt.k, opt.max_iterations, rng, centres, groups);
      done += w.members.size();
      for (size_t c = 0; c < centres.size(); ++c) {
        const uint32_t id = static_cast<uint32_t>(nodes.parents.size());
        nodes.parents.push_back(w.node);
        nodes.desc.push_back(centres[c]);
        if (w.level + 1 < opt.levels && groups[c].size() > 1)
          queue.push_back(Work{id, w.level + 1, std::move(groups[c])});
        else
          done += groups[c].size() * (remaining_levels - 1);
      }
    }
    if (progress) progress(done, total);
  }
  return nodes;
}

// Per word: how many training descriptors and how many images reach it.
struct WordCounts {
  std::vector<uint32_t> descriptors, images;
};

WordCounts countWords(const Vocabulary& tree, const TrainingSet& t) {
  const size_t words = tree.size();
  WordCounts c{std::vector<uint32_t>(words, 0), std::vector<uint32_t>(words, 0)};
  std::vector<uint32_t> last_image(words, 0xffffffffu);
  for (size_t i = 0; i < t.data.size(); ++i) {
    const uint32_t w = tree.transform(reinterpret_cast<const uint8_t*>(t.data[i].data()));
    ++c.descriptors[w];
    if (last_image[w] != t.image_of[i]) {
      last_image[w] = t.image_of[i];
      ++c.images[w];
    }
  }
  return c;
}

// Node weights: IDF on the words (when the weighting uses it, else 1), 0 on inner nodes (never
// used; keeps files comparable with DBoW2's).
std::vector<double> nodeWeights(const Vocabulary& tree, const Nodes& nodes, const WordCounts& c,
                                size_t n_images, Weighting weighting) {
  const size_t n = nodes.parents.size();
  std::vector<double> weights(n, 1.0);
  if (weighting == Weighting::TfIdf || weighting == Weighting::Idf) {
    for (size_t w = 0; w < c.images.size(); ++w) {
      // As DBoW2: log(N / n_i); words no training image reaches keep weight 0 (ignored).
      const double idf = c.images[w] > 0 ? std::log(static_cast<double>(n_images) / c.images[w]) : 0.0;
      weights[tree.wordNode(static_cast<WordId>(w))] = idf;
    }
  }
  std::vector<uint8_t> is_leaf(n, 1);
  for (size_t i = 1; i < n; ++i) is_leaf[nodes.parents[i]] = 0;
  for (size_t i = 0; i < n; ++i)
    if (!is_leaf[i]) weights[i] = 0.0;
  return weights;
}

void fillReport(const TrainerOptions& opt, const TrainingSet& t, size_t n_nodes, const WordCounts& c,
                TrainingReport& report) {
  report.images = t.n_images;
  report.descriptors = t.data.size();
  report.nodes = n_nodes;
  report.words = c.descriptors.size();
  report.capacity = std::pow(static_cast<double>(opt.k), opt.levels);
  std::vector<double> counts;
  for (size_t w = 0; w < c.descriptors.size(); ++w) {
    if (c.descriptors[w] > 0) ++report.words_hit;
    if (c.images[w] >= 2) ++report.words_in_two_images;
    counts.push_back(c.descriptors[w]);
  }
  const Summary s = summarize(counts);
  report.mean_descriptors_per_word = s.mean;
  report.median_descriptors_per_word = s.median;
}

}  // namespace

std::shared_ptr<Vocabulary> trainVocabulary(const std::vector<cv::Mat>& images,
                                            const TrainerOptions& opt, TrainingReport* report,
                                            const std::function<void(size_t, size_t)>& progress) {
  if (opt.k < 2 || opt.k > 1000)
    throw Error("vocabulary training: k must be in 2..1000, got " + std::to_string(opt.k));
  if (opt.levels < 1 || opt.levels > 12)
    throw Error("vocabulary training: levels must be in 1..12, got " + std::to_string(opt.levels));
  const TrainingSet t = gatherDescriptors(images, opt.k);

  Stopwatch sw;
  const Nodes nodes = growTree(t.data, opt, progress);
  const double cluster_s = sw.ms() / 1000.0;
  sw.restart();

  // The tree alone (unit weights) gives each training descriptor its word; the weights follow.
  const size_t n = nodes.parents.size();
  std::vector<uint8_t> desc(n * kDescriptorBytes);
  for (size_t i = 0; i < n; ++i) std::memcpy(&desc[i * kDescriptorBytes], nodes.desc[i].data(), kDescriptorBytes);
  auto tree = Vocabulary::fromNodes(opt.k, opt.levels, opt.weighting, Scoring::L1, nodes.parents, desc,
                                    std::vector<double>(n, 1.0), {}, "vocabulary training");
  const WordCounts counts = countWords(*tree, t);
  auto vocab = Vocabulary::fromNodes(opt.k, opt.levels, opt.weighting, Scoring::L1, nodes.parents, desc,
                                     nodeWeights(*tree, nodes, counts, t.n_images, opt.weighting), {},
                                     "vocabulary training");
  if (report) {
    fillReport(opt, t, n, counts, *report);
    report->cluster_seconds = cluster_s;
    report->weight_seconds = sw.ms() / 1000.0;
  }
  return vocab;
}

}  // namespace vocabulary
}  // namespace yolo_slam
