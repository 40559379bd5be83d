// Asynchronous detection: the stream never waits for the detector, a waiting frame is replaced
// by a newer one, results reach one frame each and expire with age.
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/detection/async_detector.h"

#include "support/thread_nice.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

using namespace yolo_slam;
using namespace yolo_slam::detection;

namespace {

// A detector that holds every frame until released, then returns one box whose x is the
// image's first pixel value (so a result names the frame it came from).
class GatedDetector : public Detector {
 public:
  Boxes detect(const cv::Mat& bgr) override {
    std::unique_lock<std::mutex> lk(m_);
    started_.fetch_add(1);
    cv_.wait(lk, [this] { return open_; });
    Box b;
    b.rect = cv::Rect2f(static_cast<float>(bgr.at<uchar>(0, 0)), 0.f, 10.f, 10.f);
    b.score = 0.9f;
    return {b};
  }
  std::string description() const override { return "gated test detector"; }
  void open() {
    {
      std::lock_guard<std::mutex> lk(m_);
      open_ = true;
    }
    cv_.notify_all();
  }
  int started() const { return started_.load(); }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  bool open_ = false;
  std::atomic<int> started_{0};
};

cv::Mat imageOf(int value) { return cv::Mat(4, 4, CV_8UC1, cv::Scalar(value)); }

}  // namespace

TEST(AsyncDetector, FramesFlowWhileTheDetectorIsBusyAndOnlyTheNewestWaits) {
  auto gated = std::make_unique<GatedDetector>();
  GatedDetector* gate = gated.get();
  AsyncDetector async(std::move(gated));
  async.offer(imageOf(0), 0, 0.0);
  while (gate->started() < 1) std::this_thread::yield();  // frame 0 is being detected
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 1; i < 50; ++i) async.offer(imageOf(i), i, i / 30.0);  // never blocks
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(1));
  EXPECT_FALSE(async.newest().has_value());  // boxes withheld: nothing to use yet
  gate->open();
  async.waitIdle();
  const AsyncDetectionCounts c = async.counts();
  EXPECT_EQ(c.offered, 50);
  EXPECT_EQ(c.detected, 2);  // the frame taken first, then the newest one: no backlog
  EXPECT_EQ(c.replaced, 48);
  ASSERT_TRUE(async.newest().has_value());
  EXPECT_EQ(async.newest()->frame, 49);
  EXPECT_FLOAT_EQ(async.newest()->boxes.at(0).rect.x, 49.f);
}

// A detector that answers at once with no boxes.
class InstantDetector : public Detector {
 public:
  Boxes detect(const cv::Mat&) override { return {}; }
  std::string description() const override { return "instant test detector"; }
};

TEST(AsyncDetector, AMinimumIntervalKeepsFramesFromTheDetector) {
  AsyncDetector async(std::make_unique<InstantDetector>(), 0.09);
  // 30 Hz for one second: every third frame is taken (0.1 s apart), the rest never queue.
  for (int i = 0; i < 30; ++i) {
    async.offer(imageOf(i), i, i / 30.0);
    async.waitIdle();
  }
  AsyncDetectionCounts c = async.counts();
  EXPECT_EQ(c.offered, 30);
  EXPECT_EQ(c.detected, 10);  // frames 0, 3, 6, ... 27
  EXPECT_EQ(c.throttled, 20);
  EXPECT_EQ(c.replaced, 0);
  EXPECT_EQ(async.newest()->frame, 27);
  // A stamp before the last one taken is a new stream: detected at once.
  async.offer(imageOf(0), 30, 0.0);
  async.waitIdle();
  EXPECT_EQ(async.counts().detected, 11);
  EXPECT_EQ(async.newest()->frame, 30);
}

TEST(AsyncDetector, WaitForFrameInReturnsOnceAResultThatRecentIsThere) {
  auto gated = std::make_unique<GatedDetector>();
  GatedDetector* gate = gated.get();
  AsyncDetector async(std::move(gated));
  async.offer(imageOf(5), 5, 0.0);
  std::atomic<bool> returned{false};
  bool got = false;
  std::thread waiter([&] {
    got = async.waitForFrameIn(4, 6, imageOf(6), 0.2);
    returned = true;
  });
  while (gate->started() < 1) std::this_thread::yield();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(returned.load());  // frame 5 is still being detected: the stream waits
  gate->open();
  waiter.join();
  EXPECT_TRUE(got);
  EXPECT_EQ(async.newest()->frame, 5);
  EXPECT_TRUE(async.waitForFrameIn(5, 9, imageOf(9), 0.3));  // already there: no wait
  EXPECT_EQ(async.counts().reoffered, 0);
}

// The detector took a later frame than the one waiting (frames are offered as they arrive): the
// waiting frame is offered again rather than screened with boxes older than the lag allows.
TEST(AsyncDetector, WaitForFrameInOffersAFrameTheDetectorSkippedAgain) {
  auto gated = std::make_unique<GatedDetector>();
  GatedDetector* gate = gated.get();
  AsyncDetector async(std::move(gated));
  async.offer(imageOf(0), 0, 0.0);
  while (gate->started() < 1) std::this_thread::yield();  // frame 0 is being detected
  async.offer(imageOf(1), 1, 1 / 30.0);
  async.offer(imageOf(2), 2, 2 / 30.0);  // replaces frame 1: the detector will take frame 2
  bool got = false;
  std::thread waiter([&] { got = async.waitForFrameIn(1, 1, imageOf(1), 1 / 30.0); });
  while (async.counts().reoffered < 1) std::this_thread::yield();  // frame 1 waits again
  gate->open();
  waiter.join();
  EXPECT_TRUE(got);
  EXPECT_EQ(async.newestUpTo(1)->frame, 1);
  EXPECT_FLOAT_EQ(async.newestUpTo(1)->boxes.at(0).rect.x, 1.f);
  async.waitIdle();
  const AsyncDetectionCounts c = async.counts();
  EXPECT_EQ(c.offered, 3);
  EXPECT_EQ(c.reoffered, 1);
  EXPECT_EQ(c.detected, 2);  // frames 0 and 1; frame 2 gave way to the frame offered again
  EXPECT_EQ(c.detected + c.replaced, c.offered + c.reoffered);
}

// Frames are offered as they arrive, ahead of the frame being screened: that frame must never
// get the boxes of a later image.
TEST(AsyncDetector, NewestUpToNeverHandsAFrameTheResultOfALaterOne) {
  AsyncDetector async(std::make_unique<InstantDetector>());
  EXPECT_FALSE(async.newestUpTo(10).has_value());
  for (long i : {2, 4, 6}) {
    async.offer(imageOf(static_cast<int>(i)), i, i / 30.0);
    async.waitIdle();
  }
  EXPECT_FALSE(async.newestUpTo(1).has_value());
  EXPECT_EQ(async.newestUpTo(3)->frame, 2);
  EXPECT_EQ(async.newestUpTo(5)->frame, 4);
  EXPECT_EQ(async.newestUpTo(6)->frame, 6);
  EXPECT_EQ(async.newestUpTo(100)->frame, 6);
  EXPECT_EQ(async.newest()->frame, 6);
  // Only the last few results are kept: far behind the detector there is nothing to hand out.
  for (long i = 7; i < 20; ++i) {
    async.offer(imageOf(static_cast<int>(i)), i, i / 30.0);
    async.waitIdle();
  }
  EXPECT_FALSE(async.newestUpTo(6).has_value());
  EXPECT_EQ(async.newestUpTo(18)->frame, 18);
}

TEST(AsyncDetector, TheDetectionThreadRunsAtDetectionThreadNice) {
  const int base = getpriority(PRIO_PROCESS, 0);
  AsyncDetector async(std::make_unique<InstantDetector>(), 0, 6);
  const int expected = test_support::niceAbove(base, 6);
  EXPECT_EQ(test_support::waitForThreadNice("ys_detect", expected), expected);
}

TEST(AsyncDetector, DetectionThreadNiceIsReadAndBounded) {
  Config cfg;
  cfg.set("Detection.threadNice", "4");
  EXPECT_EQ(AsyncDetectionOptions::load(cfg).thread_nice, 4);
  EXPECT_EQ(AsyncDetectionOptions::load(Config()).thread_nice, 0);
  cfg.set("Detection.threadNice", "25");
  EXPECT_THROW(AsyncDetectionOptions::load(cfg), Error);
}

TEST(BoxFeed, AResultServesOneFrameAndExpires) {
  BoxFeed feed(0.2);
  DetectionResult r;
  r.frame = 3;
  r.stamp = 1.0;
  r.boxes.resize(1);
  FrameBoxes a = feed.take(r, 1.05);
  EXPECT_TRUE(a.fresh);
  EXPECT_EQ(a.boxes.size(), 1u);
  EXPECT_NEAR(a.age_s, 0.05, 1e-9);
  EXPECT_NEAR(a.boxes[0].age_s, 0.05, 1e-9);  // each box says how old its image is
  // The same result again: no fresh boxes (the tracker carries them).
  EXPECT_FALSE(feed.take(r, 1.08).fresh);
  EXPECT_FALSE(feed.take(std::nullopt, 1.1).fresh);
  // A newer result that is already too old is not used.
  r.frame = 4;
  r.stamp = 1.1;
  const FrameBoxes old = feed.take(r, 1.5);
  EXPECT_FALSE(old.fresh);
  EXPECT_TRUE(old.boxes.empty());
  EXPECT_EQ(feed.expired(), 1);
}

TEST(AsyncDetectionOptions, LoadsAndRejectsNegativeAge) {
  const AsyncDetectionOptions d = AsyncDetectionOptions::load(Config());
  EXPECT_FALSE(d.enabled);
  EXPECT_DOUBLE_EQ(d.max_age_s, 0.2);
  const AsyncDetectionOptions o =
      AsyncDetectionOptions::load(Config::fromString("Detection.async: 1\nDetection.maxAge: 0.5\n"));
  EXPECT_TRUE(o.enabled);
  EXPECT_DOUBLE_EQ(o.max_age_s, 0.5);
  EXPECT_THROW(AsyncDetectionOptions::load(Config::fromString("Detection.maxAge: -1\n", "bad.yaml")), Error);
  EXPECT_EQ(d.threads, 1);
  EXPECT_DOUBLE_EQ(d.min_interval_s, 0.0);
  const AsyncDetectionOptions t = AsyncDetectionOptions::load(
      Config::fromString("Detection.asyncThreads: 2\nDetection.asyncMinInterval: 0.1\n"));
  EXPECT_EQ(t.threads, 2);
  EXPECT_DOUBLE_EQ(t.min_interval_s, 0.1);
  EXPECT_EQ(d.max_lag_frames, 3);
  EXPECT_EQ(AsyncDetectionOptions::load(Config::fromString("Detection.asyncMaxLag: 0\n")).max_lag_frames, 0);
  EXPECT_THROW(AsyncDetectionOptions::load(Config::fromString("Detection.asyncMaxLag: -1\n", "bad.yaml")), Error);
  EXPECT_THROW(AsyncDetectionOptions::load(Config::fromString("Detection.asyncThreads: 0\n", "bad.yaml")), Error);
  EXPECT_THROW(AsyncDetectionOptions::load(Config::fromString("Detection.asyncMinInterval: -0.1\n", "bad.yaml")),
               Error);
}
