// Per-thread priority: lowerThisThreadPriority raises the nice value of the calling thread only,
// capped at the kernel's maximum; runAtLowerPriority runs work on such a thread and waits.
#include "yolo_slam/common/thread_name.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <stdexcept>
#include <thread>

namespace yolo_slam {
namespace {

int niceOfThisThread() { return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid))); }

// The nice value a new thread has after lowering its priority by `delta`.
int niceAfterLowering(int delta) {
  int nice = 0;
  std::thread t([&] {
    lowerThisThreadPriority(delta, "Test.threadNice");
    nice = niceOfThisThread();
  });
  t.join();
  return nice;
}

TEST(ThreadPriority, OnlyTheCallingThreadIsLowered) {
  const int before = niceOfThisThread();
  EXPECT_EQ(niceAfterLowering(4), std::min(19, before + 4));
  EXPECT_EQ(niceOfThisThread(), before);
  EXPECT_EQ(niceAfterLowering(0), before);
}

TEST(ThreadPriority, TheNiceValueIsCappedAtTheMaximum) { EXPECT_EQ(niceAfterLowering(19), 19); }

TEST(ThreadPriority, RunAtLowerPriorityRunsNicedAndWaits) {
  const int before = niceOfThisThread();
  int nice = -100;
  runAtLowerPriority(5, "ys_test", "Test.threadNice", [&] { nice = niceOfThisThread(); });
  EXPECT_EQ(nice, std::min(19, before + 5));
  EXPECT_EQ(niceOfThisThread(), before);
  runAtLowerPriority(0, "ys_test", "Test.threadNice", [&] { nice = niceOfThisThread(); });
  EXPECT_EQ(nice, before);  // in the caller's thread
  EXPECT_THROW(runAtLowerPriority(5, "ys_test", "Test.threadNice", [] { throw std::runtime_error("x"); }),
               std::runtime_error);
}

}  // namespace
}  // namespace yolo_slam
