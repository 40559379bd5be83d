// The System's threads that take the map lock (local mapping, loop closing) keep the process's
// priority (a niced lock holder stalls tracking); their solves and the dense mapper run at the
// nice values of their settings above it (the solves: test/common/test_thread_name.cpp).
#include "yolo_slam/common/config.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"

#include "support/loop_preset.h"
#include "support/thread_nice.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

using namespace yolo_slam;
using test_support::niceAbove;
using test_support::waitForThreadNice;

TEST(SlamThreadPriority, LockHoldersKeepThePriorityTheDenseMapperIsNiced) {
  sim::SynthOptions so;
  so.preset = "static_xyz";
  so.frames = 2;
  sim::SequenceGenerator gen(so);
  slam::SystemOptions opt = slam::SystemOptions::load(Config());
  opt.slam.mapping.thread_nice = 3;
  opt.slam.loop.thread_nice = 5;
  opt.dense.enabled = true;
  opt.dense.thread_nice = 7;
  const int base = getpriority(PRIO_PROCESS, 0);
  slam::System sys(gen.camera(), opt, test_support::shippedVocabulary());
  EXPECT_EQ(waitForThreadNice("ys_dense_map", niceAbove(base, 7)), niceAbove(base, 7));
  EXPECT_EQ(waitForThreadNice("ys_local_map", base), base);
  EXPECT_EQ(waitForThreadNice("ys_loop_close", base), base);
  sys.shutdown();
}
