#pragma once
// The files a run writes (yolo_slam_run --out, --save-map): checked before the first frame, so
// an output that cannot be written fails the run before any work, and written while the run
// goes on, so a kill keeps what was estimated so far.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace yolo_slam {
namespace io {

// The run folder's files (README "What happens when things go wrong" tells their life cycle).
struct RunFiles {
  static constexpr const char* kCameraTrajectory = "CameraTrajectory.txt";
  static constexpr const char* kKeyFrameTrajectory = "KeyFrameTrajectory.txt";
  static constexpr const char* kBoxesScreened = "boxes_screened.txt";
  static constexpr const char* kFrames = "frames.txt";
  static constexpr const char* kStats = "stats.json";
  // Grown while the run goes on: tracking poses as estimated, boxes as screened, frames as
  // tracked.
  static constexpr const char* kPartialTrajectory = "CameraTrajectory.partial.txt";
  static constexpr const char* kPartialBoxes = "boxes_screened.partial.txt";
  static constexpr const char* kPartialFrames = "frames.partial.txt";

  static std::vector<std::string> all();
};

// Creates `dir` (and its parents) if missing and checks that files can be written there: a
// probe file is created and removed, and none of `names` nor their temporaries is a folder.
// Throws yolo_slam::Error naming the path, the system's reason and the fix; `flag` is the option
// that named the folder (e.g. "--out").
void prepareOutputFolder(const std::string& dir, const std::vector<std::string>& names, const std::string& flag);

// A file written at the end outside the run folder (--save-map FILE): its folder exists and is
// writable, and neither FILE nor its temporary is a folder. Error naming the path and the fix.
void checkOutputFile(const std::string& path, const std::string& flag);

// Removes the file `path` if there is one; Error naming it when it cannot be removed.
void removeFileIfPresent(const std::string& path);

// Removes the files of a previous run in `dir` (every RunFiles name and its temporary), except
// stats.json, which the caller replaces atomically: a folder never mixes two runs.
void removePreviousRun(const std::string& dir);

// A text file written while a run goes on. Each append() is flushed to the kernel, so a kill
// (SIGKILL, a crash) keeps every line appended before it (a power cut may lose the tail). A
// failing write (disk full) warns once on stderr and the file is given up: the run goes on and
// writes its final files at the end.
class IncrementalFile {
 public:
  // Creates (truncates) `path` and writes `header`; Error naming the file when it cannot.
  IncrementalFile(std::string path, const std::string& header);
  IncrementalFile(const IncrementalFile&) = delete;
  IncrementalFile& operator=(const IncrementalFile&) = delete;

  void append(const std::string& text);
  const std::string& path() const { return path_; }
  bool healthy() const { return file_ != nullptr; }
  // Closes the file and renames it to `final_path` (atomic); Error naming both when the rename
  // fails. False (and the file stays under its own name) when a write had failed: it is
  // incomplete.
  bool finishAs(const std::string& final_path);
  // Closes and removes the file.
  void remove();

 private:
  void close();

  std::string path_;
  std::unique_ptr<FILE, int (*)(FILE*)> file_;  // null once closed or given up
  bool failed_ = false;                          // a write failed: the file is incomplete
};

}  // namespace io
}  // namespace yolo_slam
