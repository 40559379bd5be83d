#include "yolo_slam/common/option_checks.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"

#include <cmath>
#include <cstdio>

namespace yolo_slam {

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  const bool above = lo_open ? v > lo : v >= lo;
  const bool below = hi_open ? v < hi : v <= hi;
  return above && below;
}

std::string Range::describe() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi)
    return std::string("in ") + (lo_open ? "(" : "[") + formatNumber(lo) + ", " + formatNumber(hi) +
           (hi_open ? ")" : "]");
  if (has_lo) return (lo_open ? "> " : ">= ") + formatNumber(lo);
  if (has_hi) return (hi_open ? "< " : "<= ") + formatNumber(hi);
  return "finite";
}

std::string configName(const Config& cfg) {
  return cfg.path().empty() ? std::string("<config>") : cfg.path();
}

std::string formatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

void rejectOption(const std::string& where, const std::string& key, const std::string& rule,
                  const std::string& got) {
  throw Error(where + ": key '" + key + "' must be " + rule + " (got " + got + ")");
}

void checkOption(const std::string& where, const std::string& key, double v, const Range& r) {
  if (!r.contains(v)) rejectOption(where, key, r.describe(), formatNumber(v));
}

int readInt(const Config& cfg, const std::string& key, int def, const Range& r) {
  const int v = cfg.getInt(key, def);
  checkOption(configName(cfg), key, v, r);
  return v;
}

double readDouble(const Config& cfg, const std::string& key, double def, const Range& r) {
  const double v = cfg.getDouble(key, def);
  checkOption(configName(cfg), key, v, r);
  return v;
}

double readPositive(const Config& cfg, const std::string& key, double def) {
  return readDouble(cfg, key, def, Range::positive());
}

double readFraction(const Config& cfg, const std::string& key, double def) {
  return readDouble(cfg, key, def, Range::fraction());
}

std::string readEnumName(const Config& cfg, const std::string& key, const std::string& def) {
  return cfg.getString(key, def);
}

namespace option_detail {

void read(const Config& cfg, const char* key, bool& v, const Range&) { v = cfg.getBool(key, v); }

void read(const Config& cfg, const char* key, int& v, const Range& r) {
  v = readInt(cfg, key, v, r);
}

void read(const Config& cfg, const char* key, unsigned& v, const Range& r) {
  v = static_cast<unsigned>(readInt(cfg, key, static_cast<int>(v), r));
}

// The float as stored is checked, so a value rounding onto a bound is judged as used.
void read(const Config& cfg, const char* key, float& v, const Range& r) {
  const float f = static_cast<float>(cfg.getDouble(key, v));
  checkOption(configName(cfg), key, f, r);
  v = f;
}

void read(const Config& cfg, const char* key, double& v, const Range& r) {
  v = readDouble(cfg, key, v, r);
}

}  // namespace option_detail
}  // namespace yolo_slam
