#include "yolo_slam/eval/stats.h"

#include <algorithm>
#include <cmath>

namespace yolo_slam {
namespace eval {

ErrorStats errorStats(const std::vector<double>& errors) {
  ErrorStats s;
  s.count = errors.size();
  if (errors.empty()) return s;
  const double n = static_cast<double>(errors.size());
  double sum = 0, sum2 = 0;
  for (double e : errors) {
    sum += e;
    sum2 += e * e;
  }
  s.rmse = std::sqrt(sum2 / n);
  s.mean = sum / n;
  double var = 0;
  for (double e : errors) var += (e - s.mean) * (e - s.mean);  // two-pass, like numpy
  s.std = std::sqrt(var / n);
  std::vector<double> v = errors;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  s.median = (v.size() % 2) ? v[m] : 0.5 * (v[m - 1] + v[m]);
  s.min = v.front();
  s.max = v.back();
  return s;
}

}  // namespace eval
}  // namespace yolo_slam
