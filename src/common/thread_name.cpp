#include "yolo_slam/common/thread_name.h"

#include "yolo_slam/common/log.h"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <exception>
#include <thread>

#include <cstring>
#include <string>

namespace yolo_slam {

void nameThisThread(const char* name) {
  constexpr size_t kMaxLength = 15;  // TASK_COMM_LEN minus the terminator
  const std::string kept(name, strnlen(name, kMaxLength));
  pthread_setname_np(pthread_self(), kept.c_str());
}

void lowerThisThreadPriority(int delta, const char* option_key) {
  if (delta <= 0) return;
  constexpr int kNiceMax = 19;
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  errno = 0;
  const int now = getpriority(PRIO_PROCESS, tid);
  if (errno == 0 && setpriority(PRIO_PROCESS, tid, std::min(kNiceMax, now + delta)) == 0) return;
  log::warn("%s %d: could not raise the thread's nice value (%s); it keeps the process's priority",
            option_key, delta, std::strerror(errno));
}

void runAtLowerPriority(int delta, const char* name, const char* option_key, const std::function<void()>& work) {
  if (delta <= 0) {
    work();
    return;
  }
  std::exception_ptr failure;
  std::thread worker([&] {
    nameThisThread(name);
    lowerThisThreadPriority(delta, option_key);
    try {
      work();
    } catch (...) {
      failure = std::current_exception();
    }
  });
  worker.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace yolo_slam
