#pragma once
// Wall-clock timing and summaries (median / mean / p95) for stats.json and benchmarks.
#include "yolo_slam/common/json.h"

#include <chrono>
#include <string>
#include <vector>

namespace yolo_slam {

class Stopwatch {
 public:
  Stopwatch() : start_(Clock::now()) {}
  void restart() { start_ = Clock::now(); }
  double ms() const {
    return std::chrono::duration<double, std::milli>(Clock::now() - start_).count();
  }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_;
};

// CPU time the calling thread has used, in milliseconds (CLOCK_THREAD_CPUTIME_ID): the work of
// a stage apart from the waiting a loaded machine adds to its wall time.
double threadCpuMs();

struct Summary {
  size_t count = 0;
  double mean = 0, median = 0, p95 = 0, min = 0, max = 0;
};

// Summary of a sample; an empty sample gives all zeros.
Summary summarize(std::vector<double> values);

// {"count":..,"median_ms":..,"mean_ms":..,"p95_ms":..}
Json summaryJsonMs(const Summary& s);

}  // namespace yolo_slam
