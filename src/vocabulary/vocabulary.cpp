#include "yolo_slam/vocabulary/vocabulary.h"

#include "yolo_slam/common/error.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>

namespace yolo_slam {
namespace vocabulary {

std::string toString(Weighting w) {
  switch (w) {
    case Weighting::TfIdf: return "tf-idf";
    case Weighting::Tf: return "tf";
    case Weighting::Idf: return "idf";
    case Weighting::Binary: return "binary";
  }
  return "unknown";
}

namespace {

void checkNodeArrays(int k, int levels, const std::vector<uint32_t>& parents, size_t n_descriptor_bytes,
                     size_t n_weights, size_t n_word_ids, const std::string& name) {
  const size_t n = parents.size();
  if (k < 2 || levels < 1 || levels > 32)
    throw Error(name + ": invalid vocabulary shape k=" + std::to_string(k) + " L=" +
                std::to_string(levels) + " (need k >= 2, 1 <= L <= 32)");
  if (n < 2) throw Error(name + ": vocabulary has no words (node count " + std::to_string(n) + ")");
  if (n > 0xfffffff0u) throw Error(name + ": too many nodes");
  if (n_descriptor_bytes != n * kDescriptorBytes || n_weights != n || (n_word_ids != 0 && n_word_ids != n))
    throw Error(name + ": node arrays have inconsistent sizes");
  for (size_t i = 1; i < n; ++i)
    if (parents[i] >= n || parents[i] == i)
      throw Error(name + ": node " + std::to_string(i) + " has invalid parent " +
                  std::to_string(parents[i]));
}

// Our layout: parent before child, parents non-decreasing, so each node's children are
// contiguous (the case for files we wrote).
bool inOurLayout(const std::vector<uint32_t>& parents) {
  for (size_t i = 1; i < parents.size(); ++i)
    if (!(parents[i] < i && (i == 1 || parents[i] >= parents[i - 1]))) return false;
  return true;
}

// The nodes in breadth-first order from the root (new index -> old index).
std::vector<uint32_t> breadthFirstOrder(const std::vector<uint32_t>& parents, const std::string& name) {
  const size_t n = parents.size();
  std::vector<uint32_t> count(n + 1, 0);
  for (size_t i = 1; i < n; ++i) ++count[parents[i] + 1];
  for (size_t i = 1; i <= n; ++i) count[i] += count[i - 1];
  std::vector<uint32_t> kids(n > 0 ? n - 1 : 0);
  std::vector<uint32_t> fill(count.begin(), count.end() - 1);
  for (size_t i = 1; i < n; ++i) kids[fill[parents[i]]++] = static_cast<uint32_t>(i);
  std::vector<uint32_t> order;
  order.reserve(n);
  order.push_back(0);
  for (size_t h = 0; h < order.size(); ++h) {
    const uint32_t o = order[h];
    for (uint32_t j = count[o]; j < count[o + 1]; ++j) order.push_back(kids[j]);
  }
  if (order.size() != n)
    throw Error(name + ": node parents form a cycle or unreachable nodes (" +
                std::to_string(n - order.size()) + " nodes not under the root)");
  return order;
}

// Word ids (new node index -> word) numbering the leaves in the input's node order, as DBoW2
// does for ORBvoc.txt.
std::vector<uint32_t> leafWordsInInputOrder(const std::vector<uint32_t>& parents,
                                            const std::vector<uint32_t>& new_of_old) {
  const size_t n = parents.size();
  std::vector<uint32_t> has_child(n, 0);
  for (size_t i = 1; i < n; ++i) has_child[parents[i]] = 1;
  std::vector<uint32_t> word_of_node(n, Vocabulary::kNoWord);
  uint32_t next = 0;
  for (size_t o = 1; o < n; ++o)
    if (!has_child[o]) word_of_node[new_of_old[o]] = next++;
  return word_of_node;
}

}  // namespace

std::shared_ptr<Vocabulary> Vocabulary::fromNodes(int k, int levels, Weighting weighting,
                                                  Scoring scoring,
                                                  std::vector<uint32_t> parents,
                                                  std::vector<uint8_t> descriptors,
                                                  std::vector<double> weights,
                                                  std::vector<uint32_t> word_ids,
                                                  const std::string& name) {
  checkNodeArrays(k, levels, parents, descriptors.size(), weights.size(), word_ids.size(), name);
  const size_t n = parents.size();
  auto v = std::shared_ptr<Vocabulary>(new Vocabulary());
  v->k_ = k;
  v->levels_ = levels;
  v->weighting_ = weighting;
  v->scoring_ = scoring;
  if (inOurLayout(parents)) {
    v->parent_ = std::move(parents);
    v->desc_ = std::move(descriptors);
    v->weight_ = std::move(weights);
    v->word_of_node_ = std::move(word_ids);
  } else {
    const std::vector<uint32_t> order = breadthFirstOrder(parents, name);
    std::vector<uint32_t> new_of_old(n);
    for (size_t i = 0; i < n; ++i) new_of_old[order[i]] = static_cast<uint32_t>(i);
    v->parent_.resize(n);
    v->desc_.resize(n * kDescriptorBytes);
    v->weight_.resize(n);
    if (!word_ids.empty()) v->word_of_node_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const uint32_t o = order[i];
      v->parent_[i] = i == 0 ? 0 : new_of_old[parents[o]];
      std::memcpy(&v->desc_[i * kDescriptorBytes], &descriptors[o * kDescriptorBytes], kDescriptorBytes);
      v->weight_[i] = weights[o];
      if (!word_ids.empty()) v->word_of_node_[i] = word_ids[o];
    }
    if (word_ids.empty()) v->word_of_node_ = leafWordsInInputOrder(parents, new_of_old);
  }
  v->parent_[0] = 0;
  v->buildChildren(name);
  return v;
}

void Vocabulary::buildChildren(const std::string& name) {
  const size_t n = parent_.size();
  first_child_.assign(n, 0);
  n_children_.assign(n, 0);
  for (size_t i = 1; i < n; ++i) {
    const uint32_t p = parent_[i];
    if (n_children_[p] == 0) first_child_[p] = static_cast<uint32_t>(i);
    ++n_children_[p];
  }
  // Depth check: parent before child, so one forward pass gives every depth.
  std::vector<uint8_t> depth(n, 0);
  for (size_t i = 1; i < n; ++i) {
    depth[i] = static_cast<uint8_t>(depth[parent_[i]] + 1);
    if (depth[i] > levels_)
      throw Error(name + ": tree is deeper than its declared L=" + std::to_string(levels_));
  }
  const bool numbered = !word_of_node_.empty();
  if (!numbered) word_of_node_.assign(n, kNoWord);
  size_t words = 0;
  for (size_t i = 0; i < n; ++i)
    if (n_children_[i] == 0) ++words;
  node_of_word_.assign(words, kNoWord);
  uint32_t next = 0;
  for (size_t i = 0; i < n; ++i) {
    const bool leaf = n_children_[i] == 0;
    if (!numbered) {
      if (leaf) word_of_node_[i] = next++;
      if (leaf) node_of_word_[word_of_node_[i]] = static_cast<uint32_t>(i);
      continue;
    }
    const uint32_t w = word_of_node_[i];
    if (leaf != (w != kNoWord))
      throw Error(name + ": node " + std::to_string(i) +
                  (leaf ? " is a leaf without a word id" : " has children but also a word id"));
    if (!leaf) continue;
    if (w >= words || node_of_word_[w] != kNoWord)
      throw Error(name + ": word id " + std::to_string(w) + " out of range or repeated");
    node_of_word_[w] = static_cast<uint32_t>(i);
  }
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(weight_[i]))
      throw Error(name + ": node " + std::to_string(i) + " has a non-finite weight");
}

int Vocabulary::nodeLevel(NodeId n) const {
  int level = 0;
  while (n != 0) {
    n = parent_.at(n);
    ++level;
  }
  return level;
}

bool Vocabulary::identical(const Vocabulary& o) const {
  return k_ == o.k_ && levels_ == o.levels_ && weighting_ == o.weighting_ && scoring_ == o.scoring_ &&
         parent_ == o.parent_ && desc_ == o.desc_ && word_of_node_ == o.word_of_node_ &&
         weight_.size() == o.weight_.size() &&
         std::memcmp(weight_.data(), o.weight_.data(), weight_.size() * sizeof(double)) == 0;
}

// ---------------------------------------------------------------------------------------------
// Transform. The descent is compiled twice: with the popcnt instruction (chosen at run time when
// the CPU has it, i.e. every x86-64 since 2008) and portable, because the project builds for
// baseline x86-64 where __builtin_popcountll is a library call (3x slower here).
// ---------------------------------------------------------------------------------------------
namespace {

template <bool kPopcnt>
__attribute__((always_inline)) inline int dist(const uint8_t* a, const uint8_t* b) {
  return descriptorDistance(a, b);
}

}  // namespace

template <bool kPopcnt>
__attribute__((always_inline)) inline uint32_t Vocabulary::descend(const uint8_t* d, int fv_level,
                                                                   NodeId* fv_node) const {
  uint32_t node = 0;
  int level = 0;
  NodeId at_level = 0;
  const uint8_t* base = desc_.data();
  while (n_children_[node] != 0) {
    const uint32_t first = first_child_[node];
    const uint32_t end = first + n_children_[node];
    uint32_t best = first;
    int best_d = dist<kPopcnt>(d, base + static_cast<size_t>(first) * kDescriptorBytes);
    for (uint32_t c = first + 1; c < end; ++c) {
      const int dc = dist<kPopcnt>(d, base + static_cast<size_t>(c) * kDescriptorBytes);
      if (dc < best_d) {
        best_d = dc;
        best = c;
      }
    }
    node = best;
    ++level;
    if (level == fv_level) at_level = node;
  }
  // A branch that ends above the direct-index level groups by its leaf.
  if (level < fv_level) at_level = node;
  if (fv_node) *fv_node = at_level;
  return node;
}

template <bool kPopcnt>
__attribute__((always_inline)) inline void Vocabulary::transformImpl(const cv::Mat& descriptors,
                                                                     BowVector& bow, FeatureVector* fv,
                                                                     int levels_up) const {
  const int fv_level = std::max(0, levels_ - std::max(0, levels_up));
  std::vector<std::pair<WordId, double>> words;
  std::vector<std::pair<NodeId, unsigned>> nodes;
  words.reserve(descriptors.rows);
  if (fv) nodes.reserve(descriptors.rows);
  for (int r = 0; r < descriptors.rows; ++r) {
    NodeId fvn = 0;
    const uint32_t leaf = descend<kPopcnt>(descriptors.ptr<uint8_t>(r), fv_level, &fvn);
    const double w = weight_[leaf];
    if (w <= 0) continue;  // DBoW2: zero-weight words carry no information
    words.emplace_back(word_of_node_[leaf], w);
    if (fv) nodes.emplace_back(fvn, static_cast<unsigned>(r));
  }
  std::sort(words.begin(), words.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  const bool accumulate = weighting_ == Weighting::TfIdf || weighting_ == Weighting::Tf;
  double sum = 0;
  for (size_t i = 0; i < words.size();) {
    size_t j = i;
    double v = 0;
    for (; j < words.size() && words[j].first == words[i].first; ++j) v += words[j].second;
    if (!accumulate) v = words[i].second;
    bow.emplace_hint(bow.end(), words[i].first, v);
    sum += v;
    i = j;
  }
  if (sum > 0)
    for (auto& kv : bow) kv.second /= sum;
  if (fv) {
    std::stable_sort(nodes.begin(), nodes.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (size_t i = 0; i < nodes.size();) {
      auto it = fv->emplace_hint(fv->end(), nodes[i].first, std::vector<unsigned>());
      for (; i < nodes.size() && nodes[i].first == it->first; ++i) it->second.push_back(nodes[i].second);
    }
  }
}

namespace {

void checkDescriptors(const cv::Mat& d) {
  if (d.empty()) return;
  if (d.type() != CV_8UC1 || d.cols != kDescriptorBytes)
    throw Error("Vocabulary::transform: descriptors must be N x 32 CV_8U (ORB), got " +
                std::to_string(d.rows) + " x " + std::to_string(d.cols) + " of type " +
                std::to_string(d.type()));
}

bool cpuHasPopcnt() {
#if defined(__x86_64__) || defined(__i386__)
  static const bool has = __builtin_cpu_supports("popcnt");
  return has;
#else
  return false;
#endif
}

}  // namespace

#if defined(__x86_64__) || defined(__i386__)
#define YS_POPCNT_TARGET __attribute__((target("popcnt")))
#else
#define YS_POPCNT_TARGET
#endif

namespace detail {
// Free functions so the target attribute applies to a whole inlined descent.
struct TransformDispatch {
  YS_POPCNT_TARGET static void fast(const Vocabulary& v, const cv::Mat& d, BowVector& bow,
                                    FeatureVector* fv, int up) {
    v.transformImpl<true>(d, bow, fv, up);
  }
  static void portable(const Vocabulary& v, const cv::Mat& d, BowVector& bow, FeatureVector* fv,
                       int up) {
    v.transformImpl<false>(d, bow, fv, up);
  }
  YS_POPCNT_TARGET static uint32_t fastOne(const Vocabulary& v, const uint8_t* d, int lvl, NodeId* n) {
    return v.descend<true>(d, lvl, n);
  }
  static uint32_t portableOne(const Vocabulary& v, const uint8_t* d, int lvl, NodeId* n) {
    return v.descend<false>(d, lvl, n);
  }
};
}  // namespace detail

void Vocabulary::transform(const cv::Mat& descriptors, BowVector& bow, FeatureVector& fv,
                           int levels_up) const {
  checkDescriptors(descriptors);
  bow.clear();
  fv.clear();
  if (descriptors.empty()) return;
  if (cpuHasPopcnt())
    detail::TransformDispatch::fast(*this, descriptors, bow, &fv, levels_up);
  else
    detail::TransformDispatch::portable(*this, descriptors, bow, &fv, levels_up);
}

void Vocabulary::transform(const cv::Mat& descriptors, BowVector& bow) const {
  checkDescriptors(descriptors);
  bow.clear();
  if (descriptors.empty()) return;
  if (cpuHasPopcnt())
    detail::TransformDispatch::fast(*this, descriptors, bow, nullptr, 0);
  else
    detail::TransformDispatch::portable(*this, descriptors, bow, nullptr, 0);
}

WordId Vocabulary::transform(const uint8_t* descriptor, int levels_up, NodeId* node_out) const {
  const int fv_level = std::max(0, levels_ - std::max(0, levels_up));
  const uint32_t leaf = cpuHasPopcnt()
                            ? detail::TransformDispatch::fastOne(*this, descriptor, fv_level, node_out)
                            : detail::TransformDispatch::portableOne(*this, descriptor, fv_level, node_out);
  return word_of_node_[leaf];
}

double Vocabulary::score(const BowVector& a, const BowVector& b) {
  if (a.empty() || b.empty()) return 0.0;
  double l1 = 0;
  auto ia = a.begin(), ib = b.begin();
  while (ia != a.end() && ib != b.end()) {
    if (ia->first < ib->first) {
      l1 += std::fabs(ia->second);
      ++ia;
    } else if (ib->first < ia->first) {
      l1 += std::fabs(ib->second);
      ++ib;
    } else {
      l1 += std::fabs(ia->second - ib->second);
      ++ia;
      ++ib;
    }
  }
  for (; ia != a.end(); ++ia) l1 += std::fabs(ia->second);
  for (; ib != b.end(); ++ib) l1 += std::fabs(ib->second);
  return std::max(0.0, 1.0 - 0.5 * l1);
}

}  // namespace vocabulary
}  // namespace yolo_slam
