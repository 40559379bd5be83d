#include "yolo_slam/common/thread_name.h"

#include <pthread.h>

#include <cstring>
#include <string>

namespace yolo_slam {

void nameThisThread(const char* name) {
  constexpr size_t kMaxLength = 15;  // TASK_COMM_LEN minus the terminator
  const std::string kept(name, strnlen(name, kMaxLength));
  pthread_setname_np(pthread_self(), kept.c_str());
}

}  // namespace yolo_slam
