#pragma once
// A temporary folder for a test, removed with its contents when the test ends.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace yolo_slam {
namespace test {

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/ys_detection_XXXXXX";
    const char* d = ::mkdtemp(tmpl);
    EXPECT_NE(d, nullptr) << "cannot create a temporary folder in /tmp";
    path_ = d ? d : "/tmp/ys_detection_failed";
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace test
}  // namespace yolo_slam
