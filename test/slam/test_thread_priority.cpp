// The System's background threads (local mapping, loop closing, dense mapping) run at the nice
// values of their settings above the process's, so tracking goes first on a busy CPU.
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

TEST(SlamThreadPriority, BackgroundThreadsRunAtTheirNiceValues) {
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
  EXPECT_EQ(waitForThreadNice("ys_local_map", niceAbove(base, 3)), niceAbove(base, 3));
  EXPECT_EQ(waitForThreadNice("ys_loop_close", niceAbove(base, 5)), niceAbove(base, 5));
  EXPECT_EQ(waitForThreadNice("ys_dense_map", niceAbove(base, 7)), niceAbove(base, 7));
  sys.shutdown();
}
