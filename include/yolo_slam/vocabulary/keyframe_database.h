#pragma once
// Inverted index word -> keyframes for place retrieval (reference keyframes now; loop closing
// and relocalization later), as ORB-SLAM2's KeyFrameDatabase but keyed by keyframe id and
// without knowledge of the covisibility graph (callers post-filter the candidates).
//
// Thread-safe: one std::shared_mutex (mutex_) guards all members; add/erase/clear take it
// exclusively, queries and accessors take it shared. No other lock is taken while it is held
// and no callback runs under it (the query filter is applied after the lock is released), so
// it can be called from any thread holding any other lock.
#include "yolo_slam/vocabulary/bow_vector.h"

#include <functional>
#include <shared_mutex>
#include <unordered_map>
#include <utility>
#include <vector>

namespace yolo_slam {
namespace vocabulary {

struct QueryOptions {
  // ORB-SLAM2: only keyframes sharing at least 0.8 x (the most words any keyframe shares with
  // the query) are scored; and at least min_common_words in absolute terms.
  double min_common_words_ratio = 0.8;
  int min_common_words = 1;
  double min_score = 0.0;                 // drop candidates scoring below this
  std::function<bool(long)> exclude;      // e.g. the query keyframe and its covisible ones
};

class KeyFrameDatabase {
 public:
  KeyFrameDatabase() = default;
  KeyFrameDatabase(const KeyFrameDatabase&) = delete;
  KeyFrameDatabase& operator=(const KeyFrameDatabase&) = delete;

  // Adds (or replaces) keyframe `id` with its bag of words.
  void add(long id, const BowVector& bow);
  // Removes keyframe `id`; returns false if it was not in the database.
  bool erase(long id);
  void clear();

  // Candidates sharing words with `bow`, scored by the L1 score, best first, at most
  // max_results (0 = all).
  std::vector<std::pair<long, double>> query(const BowVector& bow, size_t max_results,
                                             const QueryOptions& options = {}) const;
  // Number of words keyframe `id` shares with `bow` (0 if unknown).
  int commonWords(long id, const BowVector& bow) const;

  size_t size() const;
  bool contains(long id) const;

 private:
  mutable std::shared_mutex mutex_;  // guards index_ and bows_
  std::unordered_map<WordId, std::vector<long>> index_;  // word -> keyframes containing it
  std::unordered_map<long, BowVector> bows_;             // keyframe -> its bag of words
};

}  // namespace vocabulary
}  // namespace yolo_slam
