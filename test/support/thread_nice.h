#pragma once
// The nice value of this process's threads by name (/proc/self/task/<tid>/{comm,stat}), for
// the tests of the background threads' priority.
#include <dirent.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>

namespace yolo_slam {
namespace test_support {

inline std::map<std::string, int> threadNices() {
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
    constexpr int kNiceField = 17;  // the 19th field of stat, the 17th after "(comm) "
    for (int k = 0; k < kNiceField && fields >> field; ++k) {
    }
    nices[name] = std::stoi(field);
  }
  closedir(dir);
  return nices;
}

// The nice value of the thread called `name` once it has reached `expected` (threads set their
// priority as they start), or its last value after about two seconds; -100 if there is none.
inline int waitForThreadNice(const std::string& name, int expected) {
  int nice = -100;
  for (int tries = 0; tries < 200; ++tries) {
    const std::map<std::string, int> nices = threadNices();
    const auto it = nices.find(name);
    if (it != nices.end()) nice = it->second;
    if (nice == expected) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return nice;
}

// The nice value a thread gets when asked to be `delta` above this process's.
inline int niceAbove(int base, int delta) { return std::min(19, base + delta); }

}  // namespace test_support
}  // namespace yolo_slam
