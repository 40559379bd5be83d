#pragma once
// A DBoW2-style hierarchical vocabulary over 256-bit ORB descriptors: a k-ary tree of L levels
// whose leaves are the words. Descriptors descend from the root to the closest child (Hamming)
// at each level; the leaf reached is the descriptor's word.
//
// Files: our versioned binary format (fast to load, checksummed; see vocabulary.cpp for the
// layout) and, read-only plus a writer for interop tests, ORB-SLAM2's ORBvoc.txt text format.
// Vocabulary::load detects which by the file's first bytes.
//
// Immutable after construction, so one instance is shared (shared_ptr<const Vocabulary>) by
// all threads without locking.
#include "yolo_slam/vocabulary/bow_vector.h"
#include "yolo_slam/vocabulary/descriptor.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace yolo_slam {
namespace vocabulary {

// Numeric values are those of DBoW2 (and of ORBvoc.txt's header line).
enum class Weighting : int { TfIdf = 0, Tf = 1, Idf = 2, Binary = 3 };
enum class Scoring : int { L1 = 0 };  // the only scoring ORB-SLAM2 uses; others are rejected on load

std::string toString(Weighting w);

namespace detail {
struct TransformDispatch;
}

class Vocabulary {
 public:
  static constexpr uint32_t kNoWord = 0xffffffffu;

  // Nodes in any order with parent ids (node 0 is the root, parent of itself / ignored).
  // `descriptors` holds node_count x 32 bytes, `weights` one per node (used for leaves),
  // `word_ids` the word id of each leaf (kNoWord for inner nodes; empty = number the leaves in
  // node order). Throws yolo_slam::Error (prefixed by `name`) if the arrays do not form a tree
  // with at most `levels` levels, or the word ids are not 0..W-1 exactly once.
  static std::shared_ptr<Vocabulary> fromNodes(int k, int levels, Weighting weighting, Scoring scoring,
                                               std::vector<uint32_t> parents,
                                               std::vector<uint8_t> descriptors,
                                               std::vector<double> weights,
                                               std::vector<uint32_t> word_ids,
                                               const std::string& name = "<vocabulary>");

  // Binary file (by its magic) or ORB-SLAM2 text file (anything else). Throws yolo_slam::Error
  // naming the file (and line for text) if missing, truncated, corrupt or unsupported.
  static std::shared_ptr<Vocabulary> load(const std::string& path);
  static std::shared_ptr<Vocabulary> loadBinary(const std::string& path);
  static std::shared_ptr<Vocabulary> loadText(const std::string& path);
  // Atomic (writes path.tmp, then renames). Binary format / ORBvoc.txt format.
  void save(const std::string& path) const;
  void saveText(const std::string& path) const;

  // Bag-of-words of N x 32 CV_8U descriptors: `bow` gets the weighted, L1-normalised words;
  // `fv` groups descriptor indices by their ancestor node `levels_up` levels above the leaves
  // (ORB-SLAM2 uses 4 with L=6; where a branch ends higher, its leaf is used). As in DBoW2,
  // descriptors whose word has zero weight are left out of both. Empty input gives empty
  // outputs; a wrong type or width throws yolo_slam::Error.
  void transform(const cv::Mat& descriptors, BowVector& bow, FeatureVector& fv, int levels_up) const;
  void transform(const cv::Mat& descriptors, BowVector& bow) const;
  // Word of one 32-byte descriptor (and its node at levels_up, if node_out).
  WordId transform(const uint8_t* descriptor, int levels_up = 0, NodeId* node_out = nullptr) const;

  // L1 score 1 - 0.5 * |a - b|_1 in [0, 1] for L1-normalised vectors; 0 if either is empty.
  static double score(const BowVector& a, const BowVector& b);

  size_t size() const { return node_of_word_.size(); }  // number of words
  size_t nodeCount() const { return parent_.size(); }
  int branching() const { return k_; }
  int levels() const { return levels_; }
  Weighting weighting() const { return weighting_; }
  Scoring scoring() const { return scoring_; }
  double wordWeight(WordId w) const { return weight_[node_of_word_.at(w)]; }
  NodeId wordNode(WordId w) const { return node_of_word_.at(w); }
  const uint8_t* nodeDescriptor(NodeId n) const { return desc_.data() + 32 * static_cast<size_t>(n); }
  NodeId parent(NodeId n) const { return parent_.at(n); }
  int nodeLevel(NodeId n) const;  // root = 0, leaves of a full tree = levels()

  // True if both hold the same tree, descriptors, weights and word ids (bit for bit).
  bool identical(const Vocabulary& other) const;

 private:
  Vocabulary() = default;
  void buildChildren(const std::string& name);
  template <bool kPopcnt>
  void transformImpl(const cv::Mat& descriptors, BowVector& bow, FeatureVector* fv, int levels_up) const;
  template <bool kPopcnt>
  uint32_t descend(const uint8_t* d, int fv_level, NodeId* fv_node) const;
  friend struct detail::TransformDispatch;

  int k_ = 0, levels_ = 0;
  Weighting weighting_ = Weighting::TfIdf;
  Scoring scoring_ = Scoring::L1;
  // Structure of arrays, nodes in breadth-first order so each node's children are contiguous.
  std::vector<uint32_t> parent_;
  std::vector<uint32_t> first_child_;
  std::vector<uint32_t> n_children_;
  std::vector<uint8_t> desc_;      // node_count x 32
  std::vector<double> weight_;
  std::vector<uint32_t> word_of_node_;  // kNoWord for inner nodes
  std::vector<uint32_t> node_of_word_;
};

}  // namespace vocabulary
}  // namespace yolo_slam
