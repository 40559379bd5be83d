#pragma once
// Trajectories in the TUM format: one pose per line, "timestamp tx ty tz qx qy qz qw",
// camera-to-world (T_wc), '#' comment lines.
#include "yolo_slam/common/geometry.h"

#include <string>

namespace yolo_slam {
namespace io {

// Reads a TUM trajectory in file order (no sorting, duplicates kept). Quaternions are
// normalised. Throws yolo_slam::Error naming file:line on a line without exactly 8 numbers,
// a non-number, NaN/inf or a zero quaternion, and naming the file when it is missing.
// A file with no pose lines gives an empty trajectory (callers decide whether that is an error).
Trajectory readTrajectory(const std::string& path);

// Writes a TUM trajectory atomically: to "<path>.tmp", then renamed over `path`, so a failure
// never leaves a partial file. Stamps with %.6f, values with 9 significant digits; quaternions
// with qw >= 0. Throws yolo_slam::Error naming the file when it cannot be written.
void writeTrajectory(const std::string& path, const Trajectory& traj);

// The comment line a written trajectory starts with, newline included.
extern const char* const kTumTrajectoryHeader;
// One pose as writeTrajectory writes it, newline included (also the runner's incremental
// CameraTrajectory.partial.txt, so both files read the same way).
std::string formatTumPose(const StampedPose& p);

}  // namespace io
}  // namespace yolo_slam
