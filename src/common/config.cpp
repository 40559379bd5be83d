#include "yolo_slam/common/config.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/log.h"
#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/settings_keys.h"

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>

namespace yolo_slam {

namespace {

// OpenCV reports a parse error as "<name>(<line>): <what>" in cv::Exception::func (and the
// parser's own function name in err): the line and the reason, for a message that points there.
std::string parseErrorMessage(const cv::Exception& e, const std::string& name) {
  static const std::regex kAt(R"(\((\d+)\): (.*)$)");
  std::smatch m;
  if (std::regex_search(e.func, m, kAt))
    return name + ":" + m[1].str() + ": malformed YAML (" + m[2].str() + "); fix line " + m[1].str() +
           " (each setting is 'Key: value', lists are [a, b]) or restore the file from config/";
  return name + ": malformed or truncated YAML (" + e.err + " " + e.func +
         "); restore the file from config/ or compare it with config/TUM3.yaml";
}

std::shared_ptr<cv::FileStorage> openStorage(const std::string& source, bool memory,
                                             const std::string& name) {
  auto fs = std::make_shared<cv::FileStorage>();
  try {
    int flags = cv::FileStorage::READ | cv::FileStorage::FORMAT_YAML;
    if (memory) flags |= cv::FileStorage::MEMORY;
    if (!fs->open(source, flags) || !fs->isOpened()) {
      throw Error(name + ": cannot parse as YAML; check the file is complete and starts with %YAML:1.0");
    }
  } catch (const cv::Exception& e) {
    throw Error(parseErrorMessage(e, name));
  }
  return fs;
}

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The 1-based line on which `key` is set in `text`, 0 if not found.
size_t lineOfKey(const std::string& text, const std::string& key) {
  std::istringstream in(text);
  size_t n = 0;
  for (std::string line; std::getline(in, line);) {
    ++n;
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line.compare(first, key.size(), key) != 0) continue;
    const size_t colon = line.find_first_not_of(" \t", first + key.size());
    if (colon != std::string::npos && line[colon] == ':') return n;
  }
  return 0;
}

// "unknown key 'X' is ignored; did you mean 'Y'?"
std::string unknownKeyMessage(const std::string& key) {
  return "unknown key '" + key + "' is ignored; did you mean '" + nearestSettingsKey(key) +
         "'? (every key: config/TUM3.yaml)";
}

}  // namespace

Config Config::fromFile(const std::string& path) {
  if (!fileExists(path)) {
    throw Error(path + ": settings file not found; pass an existing YAML file (see config/ for examples)");
  }
  Config c;
  c.path_ = path;
  c.fs_ = openStorage(path, false, path);
  c.checkKeys(readText(path));
  return c;
}

Config Config::fromString(const std::string& yaml, const std::string& name) {
  Config c;
  c.path_ = name;
  std::string text = yaml;
  if (text.rfind("%YAML", 0) != 0) text = "%YAML:1.0\n" + text;
  c.fs_ = openStorage(text, true, name);
  c.checkKeys(text);
  return c;
}

void Config::checkKeys(const std::string& text) {
  const cv::FileNode root = fs_->root();
  if (!root.isMap()) return;
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string key = (*it).name();
    if (isKnownSettingsKey(key)) continue;
    const size_t line = lineOfKey(text, key);
    warn(path_ + (line ? ":" + std::to_string(line) : std::string()) + ": " + unknownKeyMessage(key));
  }
}

void Config::warn(const std::string& message) {
  log::warn("%s", message.c_str());
  warnings_.push_back(message);
}

cv::FileNode Config::node(const std::string& key) const {
  const auto it = override_fs_.find(key);
  if (it != override_fs_.end()) return (*it->second)["v"];
  if (!fs_) return cv::FileNode();
  return (*fs_)[key];
}

void Config::set(const std::string& key, const std::string& value) {
  if (key.empty()) throw Error("override '=" + value + "': the key is empty; use Key=value");
  const std::string name = "override " + key + "=" + value;
  override_fs_[key] = openStorage("%YAML:1.0\nv: " + value + "\n", true, name);
  override_text_[key] = value;
  if (!isKnownSettingsKey(key)) warn(name + ": " + unknownKeyMessage(key));
}

void Config::setFromAssignment(const std::string& assignment) {
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos)
    throw Error("override '" + assignment + "' has no '='; use Key=value, e.g. Screening.mode=detect");
  set(assignment.substr(0, eq), assignment.substr(eq + 1));
}

void Config::record(const std::string& key, Json value) const {
  std::lock_guard<std::mutex> lk(record_->mutex);
  record_->values[key] = std::move(value);
}

Json Config::effective() const {
  std::lock_guard<std::mutex> lk(record_->mutex);
  Json out = Json::object();
  for (const auto& kv : record_->values) out[kv.first] = kv.second;
  return out;
}

bool Config::has(const std::string& key) const {
  cv::FileNode n = node(key);
  return !n.empty() && !n.isNone();
}

void Config::fail(const std::string& key, const std::string& why) const {
  throw Error(path_ + ": key '" + key + "' " + why);
}

double Config::getDouble(const std::string& key, double def) const {
  cv::FileNode n = node(key);
  double v = def;
  if (!n.empty() && !n.isNone()) {
    if (!n.isReal() && !n.isInt()) fail(key, "must be a number");
    v = static_cast<double>(n);
  }
  record(key, jsonNumber(v));
  return v;
}

int Config::getInt(const std::string& key, int def) const {
  cv::FileNode n = node(key);
  int v = def;
  if (n.isInt()) {
    v = static_cast<int>(n);
  } else if (n.isReal()) {
    const double d = static_cast<double>(n);
    if (!std::isfinite(d) || d != std::floor(d)) fail(key, "must be an integer (got " + formatNumber(d) + ")");
    if (d < std::numeric_limits<int>::min() || d > std::numeric_limits<int>::max())
      fail(key, "is out of range (got " + formatNumber(d) + "; an integer of at most " +
                    std::to_string(std::numeric_limits<int>::max()) + ")");
    v = static_cast<int>(d);
  } else if (!n.empty() && !n.isNone()) {
    fail(key, "must be an integer");
  }
  record(key, v);
  return v;
}

bool Config::getBool(const std::string& key, bool def) const {
  cv::FileNode n = node(key);
  bool v = def;
  if (n.isInt()) {
    v = static_cast<int>(n) != 0;
  } else if (n.isString()) {
    const std::string s = static_cast<std::string>(n);
    if (s == "true" || s == "True" || s == "1") v = true;
    else if (s == "false" || s == "False" || s == "0") v = false;
    else fail(key, "must be true/false or 1/0");
  } else if (!n.empty() && !n.isNone()) {
    fail(key, "must be true/false or 1/0");
  }
  record(key, v);
  return v;
}

std::string Config::getString(const std::string& key, const std::string& def) const {
  cv::FileNode n = node(key);
  std::string v = def;
  if (!n.empty() && !n.isNone()) {
    if (!n.isString()) fail(key, "must be a string");
    v = static_cast<std::string>(n);
  }
  record(key, v);
  return v;
}

std::vector<std::string> Config::getStringList(const std::string& key,
                                               const std::vector<std::string>& def) const {
  cv::FileNode n = node(key);
  std::vector<std::string> out = def;
  if (n.isString()) {
    out = {static_cast<std::string>(n)};
  } else if (!n.empty() && !n.isNone()) {
    if (!n.isSeq()) fail(key, "must be a list of strings");
    out.clear();
    for (const auto& item : n) {
      if (!item.isString()) fail(key, "must be a list of strings");
      out.push_back(static_cast<std::string>(item));
    }
  }
  record(key, out);
  return out;
}

double Config::requireDouble(const std::string& key) const {
  if (!has(key)) fail(key, "is missing; add it (see config/TUM3.yaml for an example)");
  return getDouble(key, 0.0);
}

}  // namespace yolo_slam
