#pragma once
// ATE figure: ground truth and aligned estimate seen from above (the two axes with the largest
// extent, equal scale, metre grid and scale bar) and the translational error over time.
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/eval/ate.h"

#include <opencv2/core.hpp>

#include <string>

namespace yolo_slam {
namespace eval {

// Renders the figure (CV_8UC3). `title` is drawn at the top.
cv::Mat renderAtePlot(const Trajectory& gt, const Trajectory& est, const AteResult& ate,
                      const std::string& title);

// Renders and writes a PNG atomically. Throws yolo_slam::Error naming the file if it does not
// end in ".png" or cannot be written.
void writeAtePlot(const std::string& path, const Trajectory& gt, const Trajectory& est,
                  const AteResult& ate, const std::string& title);

}  // namespace eval
}  // namespace yolo_slam
