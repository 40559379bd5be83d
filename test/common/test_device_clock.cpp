#include "yolo_slam/common/device_clock.h"

#include <gtest/gtest.h>

using yolo_slam::DeviceClock;

namespace {
constexpr double kHostStart = 1.7e9;      // a wall-clock epoch second
constexpr uint64_t kFrameUs = 33333;      // 30 Hz device frame period
constexpr double kTol = 1e-6;             // 1 us (double precision at epoch seconds is ~0.2 us)
}  // namespace

TEST(DeviceClock, FirstFrameMapsToHostTime) {
  DeviceClock clock;
  EXPECT_NEAR(clock.toHost(5000000, kHostStart), kHostStart, kTol);
  EXPECT_EQ(clock.anchors(), 1);
}

TEST(DeviceClock, SpacingIsTheDevicesNotTheHosts) {
  DeviceClock clock;
  const uint64_t t0 = 123456789;
  const double s0 = clock.toHost(t0, kHostStart);
  // The host receives the frames late and irregularly; the stamps keep the device's period.
  const double jitter[] = {0.004, 0.020, 0.001, 0.015};
  for (int i = 1; i <= 4; ++i) {
    const double s = clock.toHost(t0 + i * kFrameUs, kHostStart + i * kFrameUs * 1e-6 + jitter[i - 1]);
    EXPECT_NEAR(s - s0, i * kFrameUs * 1e-6, kTol);
  }
  EXPECT_EQ(clock.anchors(), 1);
}

TEST(DeviceClock, InterleavedStreamsOutOfOrderKeepTheOffset) {
  DeviceClock clock;
  const uint64_t t0 = 2000000;
  clock.toHost(t0, kHostStart);
  // The depth frame of the same instant is read after the next colour frame.
  const double colour = clock.toHost(t0 + kFrameUs, kHostStart + 0.040);
  const double depth = clock.toHost(t0 + kFrameUs - 500, kHostStart + 0.041);
  EXPECT_NEAR(colour - depth, 500e-6, kTol);
  EXPECT_EQ(clock.anchors(), 1);
}

TEST(DeviceClock, RestartedDeviceClockTakesNewOffset) {
  DeviceClock clock;
  clock.toHost(10000000, kHostStart);
  // The recording looped: the device stamps start again near zero.
  EXPECT_NEAR(clock.toHost(0, kHostStart + 1.0), kHostStart + 1.0, kTol);
  EXPECT_EQ(clock.anchors(), 2);
}

TEST(DeviceClock, LargeSkewTakesNewOffset) {
  DeviceClock clock(0.5);
  clock.toHost(0, kHostStart);
  // The device says 0.1 s passed, the host 3 s (the device stalled and was reopened).
  EXPECT_NEAR(clock.toHost(100000, kHostStart + 3.0), kHostStart + 3.0, kTol);
  EXPECT_EQ(clock.anchors(), 2);
}

TEST(DeviceClock, ResetTakesNewOffsetAtNextFrame) {
  DeviceClock clock;
  clock.toHost(1000, kHostStart);
  clock.reset();
  EXPECT_NEAR(clock.toHost(2000, kHostStart + 0.2), kHostStart + 0.2, kTol);
  EXPECT_EQ(clock.anchors(), 2);
}
