#pragma once
// A private temporary folder for one test, removed with everything in it when the object goes
// out of scope, so a failed ASSERT (which returns early) leaves nothing behind. Under TMPDIR
// when set (std::filesystem::temp_directory_path), else /tmp.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace yolo_slam {
namespace test {

class TempDir {
 public:
  // prefix: the folder's name before mkdtemp's unique suffix. keep_on_failure: a test that
  // failed leaves the folder (its logs) for inspection and says where.
  explicit TempDir(const std::string& prefix = "ys_test", bool keep_on_failure = false)
      : keep_on_failure_(keep_on_failure) {
    std::error_code ec;
    std::filesystem::path base = std::filesystem::temp_directory_path(ec);
    if (ec) base = "/tmp";
    std::string tmpl = (base / (prefix + "_XXXXXX")).string();
    if (::mkdtemp(tmpl.data()) == nullptr) {
      ADD_FAILURE() << "cannot create a temporary folder under " << base.string()
                    << ": check that it exists and is writable (or set TMPDIR)";
      return;
    }
    path_ = tmpl;
  }
  ~TempDir() {
    if (path_.empty()) return;
    if (keep_on_failure_ && ::testing::Test::HasFailure()) {
      std::fprintf(stderr, "test failed: its files are kept in %s\n", path_.c_str());
      return;
    }
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  bool ok() const { return !path_.empty(); }
  const std::string& path() const { return path_; }
  // A file name inside the folder.
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
  bool keep_on_failure_ = false;
};

}  // namespace test
}  // namespace yolo_slam
