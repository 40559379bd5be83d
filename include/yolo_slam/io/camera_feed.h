#pragma once
// A recorded sequence played like a live camera: a camera thread makes frame i available at
// its stamp's offset from the first frame's; a frame the consumer has not taken when the next
// one arrives is dropped (newest wins, as a driver with a queue of one), so a slow consumer
// never falls behind the camera, it skips frames. Stamp gaps are played as playbackSchedule
// says (a long forward gap capped). yolo_slam_run --camera-rate.
#include "yolo_slam/io/playback.h"

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

namespace yolo_slam {
namespace io {

template <class Frame>
class CameraFeed {
 public:
  using Clock = std::chrono::steady_clock;
  struct Arrived {
    Frame frame;
    size_t index = 0;
    Clock::time_point due;  // when the camera gave it (latency is measured from here)
  };

  // `load(i)` runs on the camera thread (reading the images is the camera's work).
  CameraFeed(const std::vector<double>& stamps, std::function<Frame(size_t)> load,
             double max_gap_s = kMaxPlaybackGapS)
      : offsets_(playbackSchedule(stamps, max_gap_s).offsets), load_(std::move(load)), thread_([this] { run(); }) {}
  ~CameraFeed() {
    {
      std::lock_guard<std::mutex> lk(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  CameraFeed(const CameraFeed&) = delete;
  CameraFeed& operator=(const CameraFeed&) = delete;

  // Blocks until a frame is there; nullopt after the last one, or as soon as `stop()` is true
  // (looked at every kStopPollSlice: a signal handler's flag).
  std::optional<Arrived> next(const std::function<bool()>& stop = [] { return false; }) {
    std::unique_lock<std::mutex> lk(mutex_);
    while (!cv_.wait_for(lk, kStopPollSlice, [this] { return slot_.has_value() || done_; }))
      if (stop()) return std::nullopt;
    if (!slot_) return std::nullopt;
    std::optional<Arrived> a = std::move(slot_);
    slot_.reset();
    return a;
  }
  long offered() const { return locked(offered_); }
  long dropped() const { return locked(dropped_); }

 private:
  long locked(const long& v) const {
    std::lock_guard<std::mutex> lk(mutex_);
    return v;
  }
  Clock::time_point due(size_t i) const {
    const std::chrono::duration<double> t(offsets_[i]);
    return start_ + std::chrono::duration_cast<Clock::duration>(t);
  }
  // The camera's own work can fall behind too: it then goes on with the newest frame already
  // due, and the ones it skipped count as offered and dropped.
  void run() {
    start_ = Clock::now();
    for (size_t i = 0; i < offsets_.size(); ++i) {
      std::unique_lock<std::mutex> lk(mutex_);
      if (cv_.wait_until(lk, due(i), [this] { return stop_; })) break;
      size_t newest = i;
      while (newest + 1 < offsets_.size() && due(newest + 1) <= Clock::now()) ++newest;
      offered_ += static_cast<long>(newest - i);
      dropped_ += static_cast<long>(newest - i);
      i = newest;
      lk.unlock();
      Arrived a{load_(i), i, due(i)};
      lk.lock();
      ++offered_;
      if (slot_) ++dropped_;
      slot_ = std::move(a);
      cv_.notify_all();
    }
    std::lock_guard<std::mutex> lk(mutex_);
    done_ = true;
    cv_.notify_all();
  }

  const std::vector<double> offsets_;  // playbackSchedule of the stamps
  const std::function<Frame(size_t)> load_;
  // Guards slot_, done_, stop_ and the counts; taken alone (never while load_ runs).
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::optional<Arrived> slot_;
  bool done_ = false, stop_ = false;
  long offered_ = 0, dropped_ = 0;
  Clock::time_point start_;  // camera thread only
  std::thread thread_;       // declared last: starts once the members above exist
};

}  // namespace io
}  // namespace yolo_slam
