// The System's background threads (local mapping, loop closing, dense mapping) run at the nice
// values of their settings above the process's, so tracking goes first on a busy CPU.
#include "yolo_slam/common/config.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"

#include "support/loop_preset.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <dirent.h>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>

using namespace yolo_slam;

namespace {

// Nice value of each thread of this process by name (/proc/self/task/<tid>/{comm,stat}).
std::map<std::string, int> threadNices() {
  std::map<std::string, int> nices;
  DIR* dir = opendir("/proc/self/task");
  if (!dir) return nices;
  while (dirent* e = readdir(dir)) {
    if (e->d_name[0] == '.') continue;
    const std::string task = std::string("/proc/self/task/") + e->d_name;
    std::string name, stat;
    std::getline(std::ifstream(task + "/comm"), name);
    std::getline(std::ifstream(task + "/stat"), stat);
    const size_t paren = stat.rfind(')');
    if (paren == std::string::npos) continue;
    std::istringstream fields(stat.substr(paren + 2));
    std::string field;
    constexpr int kNiceField = 17;  // the 19th field of stat, the 17th after "(comm)"
    for (int k = 0; k < kNiceField && fields >> field; ++k) {
    }
    nices[name] = std::stoi(field);
  }
  closedir(dir);
  return nices;
}

// Waits until the named threads exist and have set their priority (they do so as they start).
std::map<std::string, int> waitForThreads(const std::vector<std::string>& names, int expected_nice) {
  std::map<std::string, int> nices;
  for (int tries = 0; tries < 200; ++tries) {
    nices = threadNices();
    const bool ready = std::all_of(names.begin(), names.end(), [&](const std::string& n) {
      return nices.count(n) && nices[n] == expected_nice;
    });
    if (ready) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return nices;
}

}  // namespace

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
  std::map<std::string, int> nices = waitForThreads({"ys_local_map"}, std::min(19, base + 3));
  nices = waitForThreads({"ys_loop_close"}, std::min(19, base + 5));
  nices = waitForThreads({"ys_dense_map"}, std::min(19, base + 7));
  EXPECT_EQ(nices["ys_local_map"], std::min(19, base + 3));
  EXPECT_EQ(nices["ys_loop_close"], std::min(19, base + 5));
  EXPECT_EQ(nices["ys_dense_map"], std::min(19, base + 7));
  sys.shutdown();
}
