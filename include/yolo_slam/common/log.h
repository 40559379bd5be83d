// One logging sink for the core's messages (warnings about input, loop closures, map resets).
// Tools keep the default, stderr; the ROS layer installs a sink that forwards to rosconsole, so
// under ROS nothing bypasses it.
#pragma once

#include <functional>
#include <string>

namespace yolo_slam {
namespace log {

enum class Level { Info, Warn, Error };

using Sink = std::function<void(Level, const std::string& message)>;

// Replaces the sink for every thread; an empty Sink restores stderr. Thread-safe.
void setSink(Sink sink);

// The message without a trailing newline. Thread-safe; the sink is called under a lock, so
// messages from different threads never interleave.
void write(Level level, const std::string& message);

void info(const char* format, ...) __attribute__((format(printf, 1, 2)));
void warn(const char* format, ...) __attribute__((format(printf, 1, 2)));
void error(const char* format, ...) __attribute__((format(printf, 1, 2)));

// The stderr form of a message: "warning: " / "error: " prefixes, as the tools always printed.
std::string stderrLine(Level level, const std::string& message);

}  // namespace log
}  // namespace yolo_slam
