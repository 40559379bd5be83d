#pragma once
#include <string>

namespace yolo_slam {
namespace io {

// Writes `content` to "<path>.tmp" and renames it over `path`, so readers never see a partial
// file. Throws yolo_slam::Error naming the file on failure (and removes the temporary).
void writeFileAtomic(const std::string& path, const std::string& content);

}  // namespace io
}  // namespace yolo_slam
