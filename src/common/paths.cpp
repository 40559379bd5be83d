#include "yolo_slam/common/paths.h"

#include <cstdlib>
#include <sys/stat.h>

namespace yolo_slam {

std::string sharedDir() {
  const char* env = std::getenv("YOLO_SLAM_SHARED");
  if (env && *env) return env;
  return YOLO_SLAM_DEFAULT_SHARED;
}

std::string packageDir() {
  const char* env = std::getenv("YOLO_SLAM_ROOT");
  if (env && *env) return env;
  return YOLO_SLAM_SOURCE_DIR;
}

std::string joinPath(const std::string& a, const std::string& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  if (b.front() == '/') return b;
  return a.back() == '/' ? a + b : a + "/" + b;
}

bool fileExists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool dirExists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

}  // namespace yolo_slam
