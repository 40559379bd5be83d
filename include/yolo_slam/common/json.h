#pragma once
// JSON through one library, nlohmann-json (Debian's nlohmann-json3-dev), for writing stats.json
// and the tools' --json output and for reading them back. Objects keep their members in
// insertion order, so files read top-down as they were written.
#include <nlohmann/json.hpp>

#include <string>

namespace yolo_slam {

using Json = nlohmann::ordered_json;

// A finite number, or null (JSON has no NaN or infinity).
Json jsonNumber(double v);
// num / den, or null without a denominator (nothing to take a share of).
Json jsonRatio(long num, long den);
// Two-space indented text with a trailing newline.
std::string dumpJson(const Json& j);
// Parses `text`; throws yolo_slam::Error naming `name` and the byte offset when it is not JSON.
Json parseJson(const std::string& text, const std::string& name);

}  // namespace yolo_slam
