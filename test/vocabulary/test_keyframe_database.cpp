#include "yolo_slam/vocabulary/keyframe_database.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

using namespace yolo_slam::vocabulary;

namespace {
BowVector uniform(std::initializer_list<WordId> words) {
  BowVector b;
  for (WordId w : words) b[w] = 1.0 / words.size();
  return b;
}
}  // namespace

TEST(KeyFrameDatabase, QueryScoresAndOrdersCandidates) {
  KeyFrameDatabase db;
  db.add(1, uniform({1, 2, 3, 4}));
  db.add(2, uniform({1, 2, 3, 9}));
  db.add(3, uniform({7, 8, 9, 10}));
  db.add(4, uniform({1, 20, 21, 22}));
  EXPECT_EQ(db.size(), 4u);
  const BowVector q = uniform({1, 2, 3, 4});
  QueryOptions all;
  all.min_common_words_ratio = 0;
  auto r = db.query(q, 0, all);
  ASSERT_EQ(r.size(), 3u);  // keyframe 3 shares no word
  EXPECT_EQ(r[0].first, 1);
  EXPECT_NEAR(r[0].second, 1.0, 1e-12);
  EXPECT_EQ(r[1].first, 2);
  EXPECT_NEAR(r[1].second, 0.75, 1e-12);
  EXPECT_EQ(r[2].first, 4);
  EXPECT_NEAR(r[2].second, 0.25, 1e-12);
  // Default ratio 0.8: only keyframes with >= 0.8 * 4 = 3 common words.
  r = db.query(q, 0);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(db.commonWords(2, q), 3);
  // max_results, min_score and exclusion (applied before the common-word threshold).
  EXPECT_EQ(db.query(q, 1, all).size(), 1u);
  QueryOptions hi = all;
  hi.min_score = 0.5;
  EXPECT_EQ(db.query(q, 0, hi).size(), 2u);
  QueryOptions ex;
  ex.exclude = [](long id) { return id == 1; };
  r = db.query(q, 0, ex);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].first, 2);
}

TEST(KeyFrameDatabase, EraseAndReplace) {
  KeyFrameDatabase db;
  db.add(1, uniform({1, 2}));
  db.add(2, uniform({2, 3}));
  EXPECT_TRUE(db.erase(1));
  EXPECT_FALSE(db.erase(1));
  EXPECT_FALSE(db.contains(1));
  auto r = db.query(uniform({1, 2}), 0);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].first, 2);
  db.add(2, uniform({5, 6}));  // replace: old words no longer index it
  EXPECT_TRUE(db.query(uniform({2, 3}), 0).empty());
  EXPECT_EQ(db.query(uniform({5, 6}), 0).size(), 1u);
  db.clear();
  EXPECT_EQ(db.size(), 0u);
  EXPECT_TRUE(db.query(uniform({5, 6}), 0).empty());
}

TEST(KeyFrameDatabase, ConcurrentAddEraseQuery) {
  KeyFrameDatabase db;
  std::atomic<bool> bad{false};
  auto writer = [&](long base) {
    for (long i = 0; i < 2000; ++i) {
      const long id = base + i;
      db.add(id, uniform({static_cast<WordId>(id % 50), static_cast<WordId>(id % 50 + 1)}));
      if (i % 3 == 0) db.erase(id);
    }
  };
  auto reader = [&]() {
    for (int i = 0; i < 2000; ++i) {
      auto r = db.query(uniform({static_cast<WordId>(i % 50), static_cast<WordId>(i % 50 + 1)}), 5);
      for (const auto& c : r)
        if (c.second < 0 || c.second > 1 + 1e-12) bad = true;
    }
  };
  std::thread a(writer, 0), b(writer, 100000), c(reader), d(reader);
  a.join();
  b.join();
  c.join();
  d.join();
  EXPECT_FALSE(bad);
  // 2000 adds per writer, every third erased: 1333 remain each.
  EXPECT_EQ(db.size(), 2u * 1333u);
  EXPECT_TRUE(db.contains(1));
  EXPECT_FALSE(db.contains(0));
  EXPECT_TRUE(db.contains(100001));
}
