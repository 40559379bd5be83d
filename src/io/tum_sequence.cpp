#include "yolo_slam/io/tum_sequence.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/log.h"
#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/io/association.h"
#include "yolo_slam/io/depth.h"
#include "yolo_slam/io/image_file.h"
#include "yolo_slam/io/text_table.h"
#include "yolo_slam/io/trajectory.h"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>

namespace yolo_slam {
namespace io {
namespace {

struct StampedFile {
  double stamp;
  std::string file;
};

// rgb.txt / depth.txt rows: "timestamp filename".
std::vector<StampedFile> readFileList(const std::string& path) {
  std::vector<StampedFile> out;
  for (const TextRow& row : readTextTable(path)) {
    if (row.fields.size() != 2) {
      throwAtLine(path, row.line, "expected 'timestamp filename', found " +
                                      std::to_string(row.fields.size()) + " fields");
    }
    out.push_back({parseFiniteDouble(row.fields[0], path, row.line, "timestamp"), row.fields[1]});
  }
  return out;
}

}  // namespace

TumSequence TumSequence::open(const std::string& dir, double max_diff) {
  if (!dirExists(dir)) {
    throw Error(dir + ": TUM sequence folder not found (expected rgb.txt, depth.txt inside)");
  }
  TumSequence seq;
  seq.dir_ = dir;
  const std::string assoc = joinPath(dir, "associations.txt");
  if (fileExists(assoc)) {
    seq.from_associations_ = true;
    for (const TextRow& row : readTextTable(assoc)) {
      if (row.fields.size() != 4) {
        throwAtLine(assoc, row.line, "expected 'rgb_stamp rgb_file depth_stamp depth_file', found " +
                                         std::to_string(row.fields.size()) + " fields");
      }
      TumFrame f;
      f.rgb_stamp = parseFiniteDouble(row.fields[0], assoc, row.line, "rgb timestamp");
      f.rgb_path = joinPath(dir, row.fields[1]);
      f.depth_stamp = parseFiniteDouble(row.fields[2], assoc, row.line, "depth timestamp");
      f.depth_path = joinPath(dir, row.fields[3]);
      seq.frames_.push_back(f);
    }
    if (seq.frames_.empty()) throw Error(assoc + ": no frames listed");
  } else {
    const std::string rgb_txt = joinPath(dir, "rgb.txt");
    const std::string depth_txt = joinPath(dir, "depth.txt");
    if (!fileExists(rgb_txt) || !fileExists(depth_txt)) {
      throw Error(dir + ": neither associations.txt nor both rgb.txt and depth.txt found; "
                        "is this a TUM RGB-D sequence folder?");
    }
    std::vector<StampedFile> rgb = readFileList(rgb_txt);
    std::vector<StampedFile> depth = readFileList(depth_txt);
    std::vector<double> ta, tb;
    for (const auto& r : rgb) ta.push_back(r.stamp);
    for (const auto& d : depth) tb.push_back(d.stamp);
    for (const auto& m : associate(ta, tb, 0.0, max_diff)) {
      TumFrame f;
      f.rgb_stamp = rgb[m.first].stamp;
      f.rgb_path = joinPath(dir, rgb[m.first].file);
      f.depth_stamp = depth[m.second].stamp;
      f.depth_path = joinPath(dir, depth[m.second].file);
      seq.frames_.push_back(f);
    }
    if (seq.frames_.empty()) {
      throw Error(rgb_txt + ": no rgb stamp has a depth stamp in " + depth_txt + " within " +
                  formatNumber(max_diff) + " s; the two lists must use the same clock (seconds) "
                  "and list the same recording: check both files, or write associations.txt "
                  "('rgb_stamp rgb_file depth_stamp depth_file') to pair the frames yourself");
    }
  }
  seq.readGroundTruth(joinPath(dir, "groundtruth.txt"));
  return seq;
}

void TumSequence::readGroundTruth(const std::string& path) {
  if (!fileExists(path)) return;
  try {
    gt_ = readTrajectory(path);
    has_gt_ = true;
  } catch (const Error& e) {
    // Ground truth is optional: a bad line costs the ATE, not the run.
    gt_warning_ = std::string(e.what()) + "; the sequence is run without ground truth (no ATE): fix or "
                  "remove the line";
    log::warn("%s", gt_warning_.c_str());
  }
}

const Trajectory& TumSequence::groundTruth() const {
  if (!has_gt_) throw Error(dir_ + ": sequence has no groundtruth.txt");
  return gt_;
}

const TumFrame& TumSequence::frame(size_t i) const {
  if (i >= frames_.size()) {
    throw Error(dir_ + ": frame index " + std::to_string(i) + " out of range (" +
                std::to_string(frames_.size()) + " frames)");
  }
  return frames_[i];
}

cv::Mat TumSequence::loadRgb(size_t i) const {
  const std::string& path = frame(i).rgb_path;
  if (dirExists(path)) throw Error(path + ": is a folder, expected an rgb image file; fix its line in rgb.txt or associations.txt");
  if (!fileExists(path)) throw Error(path + ": rgb image not found");
  cv::Mat img = readImage(path, cv::IMREAD_COLOR);
  if (img.empty()) throw Error(path + ": cannot decode rgb image (corrupt or unsupported format)");
  return img;
}

cv::Mat TumSequence::loadDepth(size_t i, double factor) const {
  return io::loadDepth(frame(i).depth_path, factor);
}

}  // namespace io
}  // namespace yolo_slam
