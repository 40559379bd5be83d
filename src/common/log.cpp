#include "yolo_slam/common/log.h"

#include <cstdarg>
#include <cstdio>
#include <mutex>
#include <vector>

namespace yolo_slam {
namespace log {

namespace {

std::mutex& sinkMutex() {
  static std::mutex m;
  return m;
}

// Guarded by sinkMutex().
Sink& currentSink() {
  static Sink sink;
  return sink;
}

std::string format(const char* fmt, va_list args) {
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, fmt, copy);
  va_end(copy);
  if (n <= 0) return std::string();
  std::vector<char> buf(static_cast<size_t>(n) + 1);
  std::vsnprintf(buf.data(), buf.size(), fmt, args);
  return std::string(buf.data(), static_cast<size_t>(n));
}

}  // namespace

std::string stderrLine(Level level, const std::string& message) {
  switch (level) {
    case Level::Warn: return "warning: " + message;
    case Level::Error: return "error: " + message;
    case Level::Info: break;
  }
  return message;
}

void setSink(Sink sink) {
  std::lock_guard<std::mutex> lock(sinkMutex());
  currentSink() = std::move(sink);
}

void write(Level level, const std::string& message) {
  std::lock_guard<std::mutex> lock(sinkMutex());
  if (currentSink()) {
    currentSink()(level, message);
    return;
  }
  std::fprintf(stderr, "%s\n", stderrLine(level, message).c_str());
}

#define YS_LOG_FORWARD(level)            \
  va_list args;                          \
  va_start(args, fmt);                   \
  const std::string msg = format(fmt, args); \
  va_end(args);                          \
  write(level, msg)

void info(const char* fmt, ...) { YS_LOG_FORWARD(Level::Info); }
void warn(const char* fmt, ...) { YS_LOG_FORWARD(Level::Warn); }
void error(const char* fmt, ...) { YS_LOG_FORWARD(Level::Error); }

#undef YS_LOG_FORWARD

}  // namespace log
}  // namespace yolo_slam
