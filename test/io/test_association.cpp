#include "yolo_slam/io/association.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace yolo_slam;
using Pairs = std::vector<std::pair<size_t, size_t>>;

TEST(Associate, NearestPairsSortedByFirst) {
  std::vector<double> a{3.0, 1.0, 2.0};
  std::vector<double> b{2.005, 0.99, 3.011};
  EXPECT_EQ(io::associate(a, b), (Pairs{{1, 1}, {2, 0}, {0, 2}}));
}

TEST(Associate, EachStampUsedOnceGreedyBySmallestDifference) {
  // b=1.0 is closest to a=1.005 (0.005) and to a=0.99 (0.01): the smaller difference wins,
  // a=0.99 then takes the remaining b=0.98 (0.01), not the closer-but-used 1.0.
  std::vector<double> a{0.99, 1.005};
  std::vector<double> b{0.98, 1.0};
  EXPECT_EQ(io::associate(a, b), (Pairs{{0, 0}, {1, 1}}));
  // Only one b: only one a gets it.
  EXPECT_EQ(io::associate(a, {1.0}), (Pairs{{1, 0}}));
}

TEST(Associate, StrictMaxDifferenceAndNothingWithin) {
  // associate.py keeps pairs with difference < max_difference (strict).
  EXPECT_TRUE(io::associate({1.0}, {1.5}, 0.0, 0.5).empty());
  EXPECT_EQ(io::associate({1.0}, {1.25}, 0.0, 0.5), (Pairs{{0, 0}}));
  EXPECT_TRUE(io::associate({1.0, 2.0}, {1.03, 2.05}).empty());
  EXPECT_TRUE(io::associate({}, {1.0}).empty());
  EXPECT_TRUE(io::associate({1.0}, {}).empty());
}

TEST(Associate, OffsetIsAddedToSecond) {
  // |a - (b + offset)|: b=0.5 with offset 0.5 matches a=1.0.
  EXPECT_EQ(io::associate({1.0, 5.0}, {4.0, 0.5}, 0.5, 0.02), (Pairs{{0, 1}}));
  EXPECT_TRUE(io::associate({1.0}, {0.5}, -0.5, 0.02).empty());
}

TEST(Associate, TiesBrokenByFirstStampThenSecond) {
  // a=1.0 and a=1.02 are both 0.01 from b=1.01: Python's tuple sort takes the smaller a.
  EXPECT_EQ(io::associate({1.02, 1.0}, {1.01}, 0.0, 0.05), (Pairs{{1, 0}}));
  // b=0.75 and b=1.25 are exactly 0.25 from a=1 (exact binary values, so a true tie): the
  // smaller b stamp wins.
  EXPECT_EQ(io::associate({1.0}, {1.25, 0.75}, 0.0, 0.5), (Pairs{{0, 1}}));
}

TEST(Associate, LargeStampsAndNonFiniteIgnored) {
  std::vector<double> a{1341846313.592026, 1341846316.570121, NAN};
  std::vector<double> b{1341846316.570146, 1341846313.592088, NAN};
  EXPECT_EQ(io::associate(a, b), (Pairs{{0, 1}, {1, 0}}));
}

TEST(Associate, MatchesBruteForceOnRandomStamps) {
  // Cross-check the windowed search against the literal all-pairs definition.
  std::srand(7);
  std::vector<double> a, b;
  for (int i = 0; i < 300; ++i) a.push_back(1e9 + (std::rand() % 100000) * 1e-4);
  for (int i = 0; i < 200; ++i) b.push_back(1e9 + (std::rand() % 100000) * 1e-4);
  const double offset = 0.003, max_diff = 0.01;
  struct C { double d, sa, sb; size_t i, j; };
  std::vector<C> cand;
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < b.size(); ++j) {
      double d = std::abs(a[i] - (b[j] + offset));
      if (d < max_diff) cand.push_back({d, a[i], b[j], i, j});
    }
  std::sort(cand.begin(), cand.end(), [](const C& x, const C& y) {
    return std::tie(x.d, x.sa, x.sb, x.i, x.j) < std::tie(y.d, y.sa, y.sb, y.i, y.j);
  });
  std::vector<char> ua(a.size()), ub(b.size());
  Pairs expect;
  for (const C& c : cand)
    if (!ua[c.i] && !ub[c.j]) { ua[c.i] = ub[c.j] = 1; expect.emplace_back(c.i, c.j); }
  std::sort(expect.begin(), expect.end(), [&](auto& x, auto& y) {
    return std::tie(a[x.first], b[x.second], x.first) < std::tie(a[y.first], b[y.second], y.first);
  });
  Pairs got = io::associate(a, b, offset, max_diff);
  EXPECT_GT(got.size(), 50u);
  EXPECT_EQ(got, expect);
}
