#pragma once
// Minimal JSON writing helpers (the tools print flat objects and lists; no parser needed).
#include <string>

namespace yolo_slam {

// Escapes a string for inclusion between double quotes in JSON.
std::string jsonEscape(const std::string& s);
// A number formatted for JSON ("null" for NaN/inf).
std::string jsonNumber(double v, int precision = 6);

}  // namespace yolo_slam
