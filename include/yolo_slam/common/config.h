#pragma once
// The one place where settings are read from YAML. Files are OpenCV FileStorage YAML
// ("%YAML:1.0"), the format of ORB-SLAM2 settings files, so TUM1/2/3.yaml of ORB-SLAM2 users
// load unchanged. Every module has one options struct with a static `load(const Config&)`
// that reads its own keys through this class; defaults live in the struct.
#include "yolo_slam/common/json.h"

#include <opencv2/core/persistence.hpp>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace yolo_slam {

class Config {
 public:
  // An empty configuration: every get() returns its default.
  Config() = default;

  // Opens and parses a YAML file. Throws yolo_slam::Error naming the file when it is missing,
  // unreadable or malformed (for example truncated; file:line when OpenCV names the line). A key
  // no loader reads (see common/settings_keys.h) is a warning on stderr naming file:line and the
  // nearest known key, kept in warnings().
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

  // Overrides `key` with `value`, a YAML scalar or flow list ("0.5", "detect", "[a, b]"),
  // before any options are loaded: the runner's --set and the nodelets' ~overrides. Throws
  // yolo_slam::Error naming the key when the value is not YAML; an unknown key is a warning.
  void set(const std::string& key, const std::string& value);
  // "Key=value" as given on a command line; throws yolo_slam::Error without a '='.
  void setFromAssignment(const std::string& assignment);
  const std::map<std::string, std::string>& overrides() const { return override_text_; }
  // The warnings given so far (unknown keys), as printed.
  const std::vector<std::string>& warnings() const { return warnings_; }

  // Every key read so far, with the value the getter returned (a default when the key was
  // absent): the effective options, for stats.json. Shared by copies of this Config.
  Json effective() const;

 private:
  cv::FileNode node(const std::string& key) const;
  [[noreturn]] void fail(const std::string& key, const std::string& why) const;
  void record(const std::string& key, Json value) const;
  void checkKeys(const std::string& text);  // warns about the unknown top-level keys of fs_
  void warn(const std::string& message);

  std::string path_;
  std::shared_ptr<cv::FileStorage> fs_;
  // One parsed document per override ("v: <value>"), looked up before fs_.
  std::map<std::string, std::shared_ptr<cv::FileStorage>> override_fs_;
  std::map<std::string, std::string> override_text_;
  std::vector<std::string> warnings_;
  struct Record {
    std::mutex mutex;  // guards values (options may load on several threads)
    std::map<std::string, Json> values;
  };
  std::shared_ptr<Record> record_ = std::make_shared<Record>();
};

}  // namespace yolo_slam
