#pragma once
#include <string>

namespace yolo_slam {

// Folder of the read-only shared material (paper, models, real TUM frames). Resolved from the
// YOLO_SLAM_SHARED environment variable, else the ../shared beside the source tree.
std::string sharedDir();

// Folder of this package's sources (config/, models/, vocab/). Resolved from YOLO_SLAM_ROOT,
// else the source tree the library was built from.
std::string packageDir();

// Join path parts with '/'.
std::string joinPath(const std::string& a, const std::string& b);

bool fileExists(const std::string& path);
bool dirExists(const std::string& path);

}  // namespace yolo_slam
