#include "yolo_slam/io/playback.h"

#include <algorithm>
#include <cmath>
#include <thread>

namespace yolo_slam {
namespace io {

PlaybackSchedule playbackSchedule(const std::vector<double>& stamps, double max_gap_s) {
  PlaybackSchedule s;
  s.offsets.reserve(stamps.size());
  for (size_t i = 0; i < stamps.size(); ++i) {
    if (i == 0) {
      s.offsets.push_back(0.0);
      continue;
    }
    double step = stamps[i] - stamps[i - 1];
    if (!std::isfinite(step) || step < 0) step = 0;
    if (step > max_gap_s) {
      if (s.gaps_capped++ == 0) s.first_capped = i;
      step = max_gap_s;
    }
    s.offsets.push_back(s.offsets.back() + step);
  }
  return s;
}

bool sleepUntilUnlessStopped(std::chrono::steady_clock::time_point due, const std::function<bool()>& stop) {
  using Clock = std::chrono::steady_clock;
  while (!stop()) {
    const Clock::time_point now = Clock::now();
    if (now >= due) return true;
    std::this_thread::sleep_for(std::min<Clock::duration>(due - now, kStopPollSlice));
  }
  return false;
}

}  // namespace io
}  // namespace yolo_slam
