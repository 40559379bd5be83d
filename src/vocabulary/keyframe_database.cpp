#include "yolo_slam/vocabulary/keyframe_database.h"

#include "yolo_slam/vocabulary/vocabulary.h"

#include <algorithm>
#include <mutex>

namespace yolo_slam {
namespace vocabulary {

namespace {
void removeFromIndex(std::unordered_map<WordId, std::vector<long>>& index, long id,
                     const BowVector& bow) {
  for (const auto& wv : bow) {
    auto it = index.find(wv.first);
    if (it == index.end()) continue;
    auto& list = it->second;
    list.erase(std::remove(list.begin(), list.end(), id), list.end());
    if (list.empty()) index.erase(it);
  }
}
}  // namespace

void KeyFrameDatabase::add(long id, const BowVector& bow) {
  std::unique_lock<std::shared_mutex> lock(mutex_);
  auto old = bows_.find(id);
  if (old != bows_.end()) removeFromIndex(index_, id, old->second);
  bows_[id] = bow;
  for (const auto& wv : bow) index_[wv.first].push_back(id);
}

bool KeyFrameDatabase::erase(long id) {
  std::unique_lock<std::shared_mutex> lock(mutex_);
  auto it = bows_.find(id);
  if (it == bows_.end()) return false;
  removeFromIndex(index_, id, it->second);
  bows_.erase(it);
  return true;
}

void KeyFrameDatabase::clear() {
  std::unique_lock<std::shared_mutex> lock(mutex_);
  index_.clear();
  bows_.clear();
}

size_t KeyFrameDatabase::size() const {
  std::shared_lock<std::shared_mutex> lock(mutex_);
  return bows_.size();
}

bool KeyFrameDatabase::contains(long id) const {
  std::shared_lock<std::shared_mutex> lock(mutex_);
  return bows_.count(id) != 0;
}

int KeyFrameDatabase::commonWords(long id, const BowVector& bow) const {
  std::shared_lock<std::shared_mutex> lock(mutex_);
  auto it = bows_.find(id);
  if (it == bows_.end()) return 0;
  int n = 0;
  auto a = it->second.begin();
  auto b = bow.begin();
  while (a != it->second.end() && b != bow.end()) {
    if (a->first < b->first) ++a;
    else if (b->first < a->first) ++b;
    else { ++n; ++a; ++b; }
  }
  return n;
}

std::vector<std::pair<long, double>> KeyFrameDatabase::query(const BowVector& bow, size_t max_results,
                                                             const QueryOptions& opt) const {
  std::vector<std::pair<long, int>> common;
  {
    std::shared_lock<std::shared_mutex> lock(mutex_);
    std::unordered_map<long, int> counts;
    for (const auto& wv : bow) {
      auto it = index_.find(wv.first);
      if (it == index_.end()) continue;
      for (long id : it->second) ++counts[id];
    }
    common.assign(counts.begin(), counts.end());
  }
  // The exclusion filter runs outside the lock (it may take the caller's own locks), and before
  // the common-word threshold, as ORB-SLAM2 excludes connected keyframes before counting.
  if (opt.exclude)
    common.erase(std::remove_if(common.begin(), common.end(),
                                [&](const std::pair<long, int>& c) { return opt.exclude(c.first); }),
                 common.end());
  int max_common = 0;
  for (const auto& kc : common) max_common = std::max(max_common, kc.second);
  const int min_common =
      std::max(opt.min_common_words, static_cast<int>(opt.min_common_words_ratio * max_common));
  std::vector<std::pair<long, double>> scored;
  {
    std::shared_lock<std::shared_mutex> lock(mutex_);
    for (const auto& kc : common) {
      if (kc.second < min_common) continue;
      auto it = bows_.find(kc.first);
      if (it == bows_.end()) continue;  // erased meanwhile
      const double s = Vocabulary::score(bow, it->second);
      if (s >= opt.min_score) scored.emplace_back(kc.first, s);
    }
  }
  // Ties broken by id so results are deterministic.
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) {
    return a.second != b.second ? a.second > b.second : a.first < b.first;
  });
  if (max_results > 0 && scored.size() > max_results) scored.resize(max_results);
  return scored;
}

}  // namespace vocabulary
}  // namespace yolo_slam
