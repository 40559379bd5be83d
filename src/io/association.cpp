#include "yolo_slam/io/association.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace yolo_slam {
namespace io {

std::vector<std::pair<size_t, size_t>> associate(const std::vector<double>& a,
                                                 const std::vector<double>& b, double offset,
                                                 double max_diff) {
  // associate.py forms every pair with |a - (b + offset)| < max_diff. Only b stamps inside a
  // window around each a can qualify, so b is sorted once and searched, which gives the same
  // candidate set without the O(|a| |b|) loop. The window is widened by a little so rounding
  // never drops a candidate; the exact test below decides.
  // Non-finite stamps never match (and would break the sort order).
  std::vector<size_t> b_order;
  for (size_t j = 0; j < b.size(); ++j) {
    if (std::isfinite(b[j])) b_order.push_back(j);
  }
  std::sort(b_order.begin(), b_order.end(), [&](size_t x, size_t y) { return b[x] < b[y]; });

  struct Candidate {
    double diff;
    size_t i, j;
  };
  std::vector<Candidate> cand;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!std::isfinite(a[i])) continue;
    const double slack = std::abs(max_diff) + 1e-12 * (1.0 + std::abs(a[i]) + std::abs(offset));
    const double lo = a[i] - offset - slack;
    auto it = std::lower_bound(b_order.begin(), b_order.end(), lo,
                               [&](size_t j, double v) { return b[j] < v; });
    for (; it != b_order.end(); ++it) {
      const size_t j = *it;
      if (b[j] > a[i] - offset + slack) break;
      const double d = std::abs(a[i] - (b[j] + offset));
      if (d < max_diff) cand.push_back({d, i, j});
    }
  }
  // Python sorts (diff, a, b) tuples: ties by the a stamp, then the b stamp.
  std::sort(cand.begin(), cand.end(), [&](const Candidate& x, const Candidate& y) {
    return std::tie(x.diff, a[x.i], b[x.j], x.i, x.j) < std::tie(y.diff, a[y.i], b[y.j], y.i, y.j);
  });
  std::vector<char> used_a(a.size(), 0), used_b(b.size(), 0);
  std::vector<std::pair<size_t, size_t>> matches;
  for (const Candidate& c : cand) {
    if (used_a[c.i] || used_b[c.j]) continue;
    used_a[c.i] = used_b[c.j] = 1;
    matches.emplace_back(c.i, c.j);
  }
  std::sort(matches.begin(), matches.end(),
            [&](const std::pair<size_t, size_t>& x, const std::pair<size_t, size_t>& y) {
              return std::tie(a[x.first], b[x.second], x.first) <
                     std::tie(a[y.first], b[y.second], y.first);
            });
  return matches;
}

}  // namespace io
}  // namespace yolo_slam
