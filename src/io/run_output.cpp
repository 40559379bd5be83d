#include "yolo_slam/io/run_output.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/io/atomic_file.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <fcntl.h>
#include <unistd.h>

namespace yolo_slam {
namespace io {

namespace fs = std::filesystem;

std::vector<std::string> RunFiles::all() {
  return {kCameraTrajectory, kKeyFrameTrajectory, kBoxesScreened, kFrames,
          kStats, kPartialTrajectory, kPartialBoxes, kPartialFrames};
}

namespace {

// Folder of a file path ("." for a bare name).
std::string folderOf(const std::string& path) {
  const std::string parent = fs::path(path).parent_path().string();
  return parent.empty() ? "." : parent;
}

// Creates and removes a probe file: the one reliable test (permissions, read-only mounts,
// /proc, ACLs). Returns the failure's reason, empty when the folder is writable.
std::string probeWritable(const std::string& dir) {
  const std::string probe = joinPath(dir, ".yolo_slam_probe." + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return std::strerror(errno);
  const bool wrote = ::write(fd, "x", 1) == 1;
  const int write_errno = errno;
  ::close(fd);
  ::unlink(probe.c_str());
  return wrote ? std::string() : std::strerror(write_errno);
}

void checkNotAFolder(const std::string& path, const std::string& fix) {
  if (dirExists(path)) throw Error(path + ": a folder has the name of an output file; " + fix);
}

void checkNameAndTemporary(const std::string& path, const std::string& fix) {
  checkNotAFolder(path, fix);
  checkNotAFolder(temporaryPathOf(path), fix);
}

}  // namespace

void prepareOutputFolder(const std::string& dir, const std::vector<std::string>& names, const std::string& flag) {
  if (fs::exists(dir) && !dirExists(dir))
    throw Error(dir + ": " + flag + " names a file, not a folder; give a folder (it is created if missing)");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !dirExists(dir))
    throw Error(dir + ": cannot create the output folder (" + (ec ? ec.message() : "not a folder") +
                "); choose another " + flag + " or fix the permissions of its parent");
  const std::string reason = probeWritable(dir);
  if (!reason.empty())
    throw Error(dir + ": the output folder is not writable (" + reason + "); choose another " + flag +
                " or fix its permissions");
  for (const std::string& name : names)
    checkNameAndTemporary(joinPath(dir, name), "remove or rename that folder, or choose another " + flag);
}

void checkOutputFile(const std::string& path, const std::string& flag) {
  const std::string dir = folderOf(path);
  if (!dirExists(dir)) throw Error(path + ": " + flag + " folder " + dir + " does not exist; create it first");
  const std::string reason = probeWritable(dir);
  if (!reason.empty())
    throw Error(path + ": " + flag + " folder " + dir + " is not writable (" + reason +
                "); choose another path or fix its permissions");
  checkNameAndTemporary(path, "remove or rename that folder, or give " + flag + " another path");
}

void removeFileIfPresent(const std::string& path) {
  if (std::remove(path.c_str()) != 0 && errno != ENOENT)
    throw Error(path + ": cannot remove the previous run's file (" + std::strerror(errno) +
                "); remove it by hand or choose another output folder");
}

void removePreviousRun(const std::string& dir) {
  for (const std::string& name : RunFiles::all()) {
    const std::string path = joinPath(dir, name);
    removeFileIfPresent(temporaryPathOf(path));
    if (name != RunFiles::kStats) removeFileIfPresent(path);
  }
}

IncrementalFile::IncrementalFile(std::string path, const std::string& header)
    : path_(std::move(path)), file_(std::fopen(path_.c_str(), "w"), &std::fclose) {
  if (!file_)
    throw Error(path_ + ": cannot create the file (" + std::strerror(errno) +
                "); check that the folder is writable and that no folder has this name");
  append(header);
  if (!file_) throw Error(path_ + ": cannot write the file; free disk space or choose another output folder");
}

void IncrementalFile::append(const std::string& text) {
  if (!file_) return;
  const bool ok = std::fwrite(text.data(), 1, text.size(), file_.get()) == text.size() && std::fflush(file_.get()) == 0;
  if (ok) return;
  std::fprintf(
      stderr,
      "\nwarning: %s: write failed (%s); it is no longer updated (the final files are still written at the end)\n",
      path_.c_str(), std::strerror(errno));
  file_.reset();
  failed_ = true;
}

void IncrementalFile::close() {
  if (file_ && std::fclose(file_.release()) != 0)
    std::fprintf(stderr, "\nwarning: %s: closing failed (%s)\n", path_.c_str(), std::strerror(errno));
}

bool IncrementalFile::finishAs(const std::string& final_path) {
  close();
  if (failed_) return false;
  if (std::rename(path_.c_str(), final_path.c_str()) != 0)
    throw Error(final_path + ": cannot rename " + path_ + " to it (" + std::strerror(errno) +
                "); the data is still in " + path_);
  return true;
}

void IncrementalFile::remove() {
  close();
  std::remove(path_.c_str());
}

}  // namespace io
}  // namespace yolo_slam
