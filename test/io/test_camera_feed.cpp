// A recorded sequence played like a camera: frames at their stamps, newest wins, drops counted.
#include "yolo_slam/io/camera_feed.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

using namespace yolo_slam;

namespace {
std::vector<double> stamps(size_t n, double period) {
  std::vector<double> s;
  for (size_t i = 0; i < n; ++i) s.push_back(100.0 + i * period);
  return s;
}
}  // namespace

TEST(CameraFeed, AFastConsumerGetsEveryFrameInOrder) {
  io::CameraFeed<int> feed(stamps(20, 0.01), [](size_t i) { return static_cast<int>(i) * 10; });
  std::vector<size_t> got;
  while (auto a = feed.next()) {
    EXPECT_EQ(a->frame, static_cast<int>(a->index) * 10);
    got.push_back(a->index);
  }
  EXPECT_EQ(feed.offered(), 20);
  EXPECT_EQ(static_cast<long>(got.size()) + feed.dropped(), 20);
  EXPECT_LE(feed.dropped(), 2);  // a loaded machine may drop one; the consumer is far faster
  for (size_t k = 1; k < got.size(); ++k) EXPECT_LT(got[k - 1], got[k]);
}

TEST(CameraFeed, ASlowConsumerDropsFramesAndNeverFallsBehind) {
  // 30 Hz camera, a consumer that takes 100 ms a frame: about two frames of three dropped.
  io::CameraFeed<int> feed(stamps(30, 1.0 / 30), [](size_t i) { return static_cast<int>(i); });
  long processed = 0;
  double worst_lag_s = 0;
  while (auto a = feed.next()) {
    ++processed;
    const double lag = std::chrono::duration<double>(std::chrono::steady_clock::now() - a->due).count();
    worst_lag_s = std::max(worst_lag_s, lag);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(feed.offered(), 30);
  EXPECT_EQ(processed + feed.dropped(), 30);
  EXPECT_GE(feed.dropped(), 15);
  EXPECT_LE(processed, 15);
  // Newest wins: a frame taken is never older than one consumer step (generous for CI load).
  EXPECT_LT(worst_lag_s, 0.5);
}
