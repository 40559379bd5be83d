#include "yolo_slam/common/config.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"

#include <opencv2/core.hpp>

namespace yolo_slam {

namespace {

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
    throw Error(name + ": malformed or truncated YAML (" + e.err +
                "); restore the file from config/ or fix the line reported");
  }
  return fs;
}

}  // namespace

Config Config::fromFile(const std::string& path) {
  if (!fileExists(path)) {
    throw Error(path + ": settings file not found; pass an existing YAML file (see config/ for examples)");
  }
  Config c;
  c.path_ = path;
  c.fs_ = openStorage(path, false, path);
  return c;
}

Config Config::fromString(const std::string& yaml, const std::string& name) {
  Config c;
  c.path_ = name;
  std::string text = yaml;
  if (text.rfind("%YAML", 0) != 0) text = "%YAML:1.0\n" + text;
  c.fs_ = openStorage(text, true, name);
  return c;
}

cv::FileNode Config::node(const std::string& key) const {
  if (!fs_) return cv::FileNode();
  return (*fs_)[key];
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
  if (n.empty() || n.isNone()) return def;
  if (!n.isReal() && !n.isInt()) fail(key, "must be a number");
  return static_cast<double>(n);
}

int Config::getInt(const std::string& key, int def) const {
  cv::FileNode n = node(key);
  if (n.empty() || n.isNone()) return def;
  if (n.isInt()) return static_cast<int>(n);
  if (n.isReal()) {
    double v = static_cast<double>(n);
    if (v != static_cast<double>(static_cast<int>(v))) fail(key, "must be an integer");
    return static_cast<int>(v);
  }
  fail(key, "must be an integer");
}

bool Config::getBool(const std::string& key, bool def) const {
  cv::FileNode n = node(key);
  if (n.empty() || n.isNone()) return def;
  if (n.isInt()) return static_cast<int>(n) != 0;
  if (n.isString()) {
    std::string s = static_cast<std::string>(n);
    if (s == "true" || s == "True" || s == "1") return true;
    if (s == "false" || s == "False" || s == "0") return false;
  }
  fail(key, "must be true/false or 1/0");
}

std::string Config::getString(const std::string& key, const std::string& def) const {
  cv::FileNode n = node(key);
  if (n.empty() || n.isNone()) return def;
  if (!n.isString()) fail(key, "must be a string");
  return static_cast<std::string>(n);
}

std::vector<std::string> Config::getStringList(const std::string& key,
                                               const std::vector<std::string>& def) const {
  cv::FileNode n = node(key);
  if (n.empty() || n.isNone()) return def;
  std::vector<std::string> out;
  if (n.isString()) {
    out.push_back(static_cast<std::string>(n));
    return out;
  }
  if (!n.isSeq()) fail(key, "must be a list of strings");
  for (const auto& item : n) {
    if (!item.isString()) fail(key, "must be a list of strings");
    out.push_back(static_cast<std::string>(item));
  }
  return out;
}

double Config::requireDouble(const std::string& key) const {
  if (!has(key)) fail(key, "is missing; add it (see config/TUM3.yaml for an example)");
  return getDouble(key, 0.0);
}

}  // namespace yolo_slam
