#pragma once
// Error statistics as the TUM benchmark scripts print them (numpy semantics).
#include <string>
#include <vector>

namespace yolo_slam {
namespace eval {

struct ErrorStats {
  size_t count = 0;
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;
};

// rmse = sqrt(sum e^2 / n), median = numpy.median (mean of the two middle values for even n),
// std = numpy.std (population, ddof 0). An empty sample gives all zeros.
ErrorStats errorStats(const std::vector<double>& errors);

}  // namespace eval
}  // namespace yolo_slam
