// Playing stamps: long forward gaps capped, backward steps played at once, and a wait that ends
// on a stop request instead of sleeping through it.
#include "yolo_slam/io/camera_feed.h"
#include "yolo_slam/io/playback.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>

using namespace yolo_slam;

namespace {
constexpr auto kStopAfter = std::chrono::milliseconds(100);
const auto kFarFuture = std::chrono::hours(1);
}  // namespace

TEST(Playback, ForwardGapsAreCappedAndBackwardStepsPlayedAtOnce) {
  const io::PlaybackSchedule s = io::playbackSchedule({10.0, 10.5, 1010.5, 1011.0, 1000.0, 1000.25, NAN, 1000.5}, 2.0);
  ASSERT_EQ(s.offsets.size(), 8u);
  const std::vector<double> want = {0.0, 0.5, 2.5, 3.0, 3.0, 3.25, 3.25, 3.25};
  for (size_t i = 0; i < want.size(); ++i) EXPECT_DOUBLE_EQ(s.offsets[i], want[i]) << i;
  EXPECT_EQ(s.gaps_capped, 1u);
  EXPECT_EQ(s.first_capped, 2u);
}

TEST(Playback, RegularStampsAreKept) {
  const io::PlaybackSchedule s = io::playbackSchedule({5.0, 5.1, 5.2});
  EXPECT_EQ(s.gaps_capped, 0u);
  EXPECT_NEAR(s.offsets[2], 0.2, 1e-12);
}

TEST(Playback, SleepEndsOnAStopRequest) {
  std::atomic<bool> stop{false};
  std::thread signaller([&] {
    std::this_thread::sleep_for(kStopAfter);
    stop = true;
  });
  // Without the stop check this would sleep an hour (the test would hang, not fail slowly).
  EXPECT_FALSE(io::sleepUntilUnlessStopped(std::chrono::steady_clock::now() + kFarFuture, [&] { return stop.load(); }));
  signaller.join();
  EXPECT_TRUE(io::sleepUntilUnlessStopped(std::chrono::steady_clock::now(), [] { return false; }));
}

TEST(Playback, CameraFeedWaitEndsOnAStopRequest) {
  // The second frame is due an hour later without the cap; with it, still far beyond the stop.
  io::CameraFeed<int> feed(
      {0.0, 3600.0}, [](size_t i) { return static_cast<int>(i); }, 3600.0);
  ASSERT_TRUE(feed.next().has_value());
  std::atomic<bool> stop{false};
  std::thread signaller([&] {
    std::this_thread::sleep_for(kStopAfter);
    stop = true;
  });
  EXPECT_FALSE(feed.next([&] { return stop.load(); }).has_value());
  signaller.join();
}

TEST(Playback, CameraFeedCapsALongGap) {
  io::CameraFeed<int> feed(
      {0.0, 0.01, 3600.0}, [](size_t i) { return static_cast<int>(i); }, 0.05);
  size_t got = 0;
  while (feed.next()) ++got;  // would take an hour without the cap
  EXPECT_EQ(got + static_cast<size_t>(feed.dropped()), 3u);
}
