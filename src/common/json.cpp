#include "yolo_slam/common/json.h"

#include "yolo_slam/common/error.h"

#include <cmath>

namespace yolo_slam {

Json jsonNumber(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json jsonRatio(long num, long den) {
  return den > 0 ? Json(static_cast<double>(num) / static_cast<double>(den)) : Json(nullptr);
}

std::string dumpJson(const Json& j) { return j.dump(2) + "\n"; }

Json parseJson(const std::string& text, const std::string& name) {
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    throw Error(name + ": not valid JSON (byte " + std::to_string(e.byte) + "): " + e.what());
  }
}

}  // namespace yolo_slam
