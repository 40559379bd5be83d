#pragma once
// A TUM RGB-D sequence folder: rgb.txt, depth.txt (or an associations file) and optionally
// groundtruth.txt, with image paths relative to the folder.
#include "yolo_slam/common/geometry.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace yolo_slam {
namespace io {

struct TumFrame {
  double rgb_stamp = 0;
  std::string rgb_path;  // absolute or relative to the current directory (folder prepended)
  double depth_stamp = 0;
  std::string depth_path;
};

class TumSequence {
 public:
  // Opens `dir`. If dir/associations.txt exists its rows "rgb_stamp rgb_file depth_stamp
  // depth_file" are used as they are (ORB-SLAM2's association file format, rgb first);
  // otherwise rgb.txt and depth.txt are associated like TUM's associate.py (offset 0,
  // `max_diff` seconds). dir/groundtruth.txt is read if present; a bad line in it is a warning
  // (groundTruthWarning(), also printed on stderr) and the sequence has no ground truth. Throws
  // yolo_slam::Error naming the folder or file:line when the folder or the lists are missing or
  // malformed, or when no frame pair is found.
  static TumSequence open(const std::string& dir, double max_diff = 0.02);

  const std::string& dir() const { return dir_; }
  const std::vector<TumFrame>& frames() const { return frames_; }
  size_t size() const { return frames_.size(); }
  bool hasGroundTruth() const { return has_gt_; }
  const Trajectory& groundTruth() const;  // throws if there is none
  // Why a groundtruth.txt present was not used ("" when it was, or when there is none).
  const std::string& groundTruthWarning() const { return gt_warning_; }
  // True when the frames came from an associations file rather than rgb.txt/depth.txt.
  bool fromAssociationsFile() const { return from_associations_; }

  // BGR CV_8UC3 image of frame i; Error naming the file if missing or corrupt.
  cv::Mat loadRgb(size_t i) const;
  // CV_32F metres of frame i (see io::loadDepth).
  cv::Mat loadDepth(size_t i, double factor) const;

 private:
  const TumFrame& frame(size_t i) const;
  void readGroundTruth(const std::string& path);

  std::string dir_;
  std::vector<TumFrame> frames_;
  bool has_gt_ = false;
  bool from_associations_ = false;
  Trajectory gt_;
  std::string gt_warning_;
};

}  // namespace io
}  // namespace yolo_slam
