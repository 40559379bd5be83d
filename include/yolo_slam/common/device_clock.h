#pragma once
// Frame stamps from a camera's own clock (ROS-free). A device stamps each frame in microseconds
// since it started; DeviceClock maps that to host time (seconds) by one offset taken at the first
// frame, so the spacing of the stamps is the device's and not the host's scheduling jitter
// (openni2_camera's use_device_time). A device clock that restarts (camera re-plugged, recording
// looped) or drifts too far from the host (more than max_skew_s) takes a new offset.
#include <cmath>
#include <cstdint>

namespace yolo_slam {

class DeviceClock {
 public:
  // Mapped stamps further than this from the host clock mean the device clock was reset.
  static constexpr double kDefaultMaxSkewS = 1.0;

  explicit DeviceClock(double max_skew_s = kDefaultMaxSkewS) : max_skew_s_(max_skew_s) {}

  // Host time (s) of a frame stamped `device_us` by the device and received at `host_now_s`.
  double toHost(uint64_t device_us, double host_now_s) {
    const double device_s = static_cast<double>(device_us) * kSecondsPerMicrosecond;
    // Only the skew tells a restart: colour and depth frames arrive interleaved, a little out of
    // stamp order, which must not move the offset.
    if (!anchored_ || std::abs(device_s + offset_s_ - host_now_s) > max_skew_s_) {
      offset_s_ = host_now_s - device_s;
      anchored_ = true;
      ++anchors_;
    }
    return device_s + offset_s_;
  }

  // The next frame takes a new offset (call when the device is reopened).
  void reset() { anchored_ = false; }

  // How many offsets were taken: 1 while the device clock runs steadily.
  int anchors() const { return anchors_; }

 private:
  static constexpr double kSecondsPerMicrosecond = 1e-6;
  double max_skew_s_;
  bool anchored_ = false;
  double offset_s_ = 0;
  int anchors_ = 0;
};

}  // namespace yolo_slam
