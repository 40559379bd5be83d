// The core's logging sink: messages reach an installed sink with their level, formatted, and an
// empty sink restores stderr.
#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "yolo_slam/common/log.h"

namespace yolo_slam {
namespace {

struct Captured {
  std::vector<std::pair<log::Level, std::string>> lines;
};

class LogSink : public ::testing::Test {
 protected:
  void SetUp() override {
    log::setSink([this](log::Level level, const std::string& m) { captured_.lines.emplace_back(level, m); });
  }
  void TearDown() override { log::setSink(log::Sink()); }
  Captured captured_;
};

TEST_F(LogSink, EachLevelReachesTheSinkFormatted) {
  log::info("loop: keyframe %d matches %d", 7, 3);
  log::warn("frame %.3f: %s", 1.5, "no depth");
  log::error("%s", "cannot open x.png");
  ASSERT_EQ(captured_.lines.size(), 3u);
  EXPECT_EQ(captured_.lines[0], std::make_pair(log::Level::Info, std::string("loop: keyframe 7 matches 3")));
  EXPECT_EQ(captured_.lines[1], std::make_pair(log::Level::Warn, std::string("frame 1.500: no depth")));
  EXPECT_EQ(captured_.lines[2], std::make_pair(log::Level::Error, std::string("cannot open x.png")));
}

TEST_F(LogSink, LongMessagesAreNotCut) {
  const std::string long_text(5000, 'x');
  log::warn("%s!", long_text.c_str());
  ASSERT_EQ(captured_.lines.size(), 1u);
  EXPECT_EQ(captured_.lines[0].second, long_text + "!");
}

TEST_F(LogSink, MessagesFromSeveralThreadsAllArrive) {
  constexpr int kThreads = 4, kEach = 200;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([t] {
      for (int i = 0; i < kEach; ++i) log::info("thread %d message %d", t, i);
    });
  for (auto& th : threads) th.join();
  EXPECT_EQ(captured_.lines.size(), static_cast<size_t>(kThreads * kEach));
}

TEST(LogStderr, AnEmptySinkWritesTheToolsFormatToStderr) {
  log::setSink(log::Sink());
  ::testing::internal::CaptureStderr();
  log::warn("frame %d: lost", 4);
  log::info("loop: closed");
  log::error("bad");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "warning: frame 4: lost\nloop: closed\nerror: bad\n");
}

}  // namespace
}  // namespace yolo_slam
