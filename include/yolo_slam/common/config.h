#pragma once
// The one place where settings are read from YAML. Files are OpenCV FileStorage YAML
// ("%YAML:1.0"), the format of ORB-SLAM2 settings files, so TUM1/2/3.yaml of ORB-SLAM2 users
// load unchanged. Every module has one options struct with a static `load(const Config&)`
// that reads its own keys through this class; defaults live in the struct.
#include <opencv2/core/persistence.hpp>

#include <memory>
#include <string>
#include <vector>

namespace yolo_slam {

class Config {
 public:
  // An empty configuration: every get() returns its default.
  Config() = default;

  // Opens and parses a YAML file. Throws yolo_slam::Error naming the file when it is missing,
  // unreadable or malformed (for example truncated).
  static Config fromFile(const std::string& path);
  // Parses YAML text (for tests); `name` is used in error messages.
  static Config fromString(const std::string& yaml, const std::string& name = "<string>");

  const std::string& path() const { return path_; }
  bool empty() const { return !fs_; }
  bool has(const std::string& key) const;

  // Typed getters. A missing key gives the default; a key of the wrong type throws
  // yolo_slam::Error naming the file and the key.
  double getDouble(const std::string& key, double def) const;
  int getInt(const std::string& key, int def) const;
  bool getBool(const std::string& key, bool def) const;
  std::string getString(const std::string& key, const std::string& def) const;
  std::vector<std::string> getStringList(const std::string& key,
                                         const std::vector<std::string>& def) const;

  // Required variants: a missing key throws yolo_slam::Error naming file and key.
  double requireDouble(const std::string& key) const;

 private:
  cv::FileNode node(const std::string& key) const;
  [[noreturn]] void fail(const std::string& key, const std::string& why) const;

  std::string path_;
  std::shared_ptr<cv::FileStorage> fs_;
};

}  // namespace yolo_slam
