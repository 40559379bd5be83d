#pragma once
#include <string>

namespace yolo_slam {
namespace io {

// Writes `content` to temporaryPathOf(path), flushes it to disk and renames it over `path`, so
// readers never see a partial file. Throws yolo_slam::Error naming the file, the system's
// reason and the fix on failure (and removes the temporary).
void writeFileAtomic(const std::string& path, const std::string& content);

// The temporary name writeFileAtomic writes first: "<path>.tmp".
std::string temporaryPathOf(const std::string& path);

}  // namespace io
}  // namespace yolo_slam
