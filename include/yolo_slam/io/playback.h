#pragma once
// Playing a recorded sequence at its stamps (yolo_slam_run --realtime and --camera-rate): when
// each frame is due, and waiting for it without becoming deaf to a stop request.
#include <chrono>
#include <cstddef>
#include <functional>
#include <vector>

namespace yolo_slam {
namespace io {

// A forward stamp gap longer than this is played as this long: a recording paused for minutes
// (or a clock jump) must not stall a run for the whole gap.
constexpr double kMaxPlaybackGapS = 2.0;
// How often a wait looks at its stop request.
constexpr std::chrono::milliseconds kStopPollSlice{50};

struct PlaybackSchedule {
  std::vector<double> offsets;  // seconds after the first frame at which frame i is due
  size_t gaps_capped = 0;       // forward gaps longer than max_gap_s
  size_t first_capped = 0;      // frame after the first capped gap (valid when gaps_capped > 0)
};

// Offsets from the stamp differences: a backward step is played at once (offset unchanged), a
// forward gap longer than max_gap_s as max_gap_s. Non-finite stamps count as no step.
PlaybackSchedule playbackSchedule(const std::vector<double>& stamps, double max_gap_s = kMaxPlaybackGapS);

// Sleeps until `due`, looking at `stop` every kStopPollSlice; false when it returned because
// stop() became true.
bool sleepUntilUnlessStopped(std::chrono::steady_clock::time_point due, const std::function<bool()>& stop);

}  // namespace io
}  // namespace yolo_slam
