#include "yolo_slam/common/timing.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <time.h>

namespace yolo_slam {

double threadCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

Summary summarize(std::vector<double> v) {
  Summary s;
  s.count = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.min = v.front();
  s.max = v.back();
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  const size_t n = v.size();
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  // Nearest-rank percentile.
  size_t rank = static_cast<size_t>(std::ceil(0.95 * static_cast<double>(n)));
  s.p95 = v[std::min(n - 1, rank == 0 ? 0 : rank - 1)];
  return s;
}

Json summaryJsonMs(const Summary& s) {
  return Json{{"count", s.count}, {"median_ms", s.median}, {"mean_ms", s.mean}, {"p95_ms", s.p95}};
}

}  // namespace yolo_slam
