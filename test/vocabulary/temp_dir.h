#pragma once
// A private temporary folder for one vocabulary test, removed with everything in it when the
// object goes out of scope, so a failed ASSERT (which returns early) leaves nothing behind.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace yolo_slam {
namespace vocab_test {

class ScopedTempDir {
 public:
  ScopedTempDir() {
    // TMPDIR is honoured (temp_directory_path); mkdtemp makes the name unique per process and test.
    std::error_code ec;
    std::filesystem::path base = std::filesystem::temp_directory_path(ec);
    if (ec) base = "/tmp";
    std::string tmpl = (base / "ys_vocab_test_XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) {
      ADD_FAILURE() << "cannot create a temporary folder under " << base.string()
                    << ": check that it exists and is writable (or set TMPDIR)";
      return;
    }
    path_ = tmpl;
  }
  ~ScopedTempDir() {
    if (path_.empty()) return;
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;

  bool ok() const { return !path_.empty(); }
  const std::string& path() const { return path_; }
  // A file name inside the folder.
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

}  // namespace vocab_test
}  // namespace yolo_slam
