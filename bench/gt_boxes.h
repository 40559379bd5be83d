#pragma once
// Person boxes of a synthetic sequence's boxes.txt (yolo_slam_synth: "rgb_stamp id class x1 y1
// x2 y2 visible_fraction"), by frame stamp, for the benchmarks that screen with ground truth.
#include "yolo_slam/detection/box.h"
#include "yolo_slam/io/text_table.h"

#include <cmath>
#include <map>
#include <string>

namespace yolo_slam {
namespace bench {

constexpr double kStampMatchS = 1e-4;

inline long stampKey(double t) { return std::lround(t / kStampMatchS); }

// Throws yolo_slam::Error naming the file and line on a malformed row.
inline std::map<long, detection::Boxes> readPersonBoxes(const std::string& path) {
  std::map<long, detection::Boxes> out;
  for (const io::TextRow& r : io::readTextTable(path)) {
    if (r.fields.size() < 7) io::throwAtLine(path, r.line, "expected 'stamp id class x1 y1 x2 y2 ...'");
    if (r.fields[2] != "person") continue;
    float c[4];
    for (int k = 0; k < 4; ++k) c[k] = static_cast<float>(io::parseFiniteDouble(r.fields[3 + k], path, r.line, "corner"));
    detection::Box b;
    b.label = "person";
    b.score = 1.f;
    b.rect = cv::Rect2f(c[0], c[1], c[2] - c[0], c[3] - c[1]);
    out[stampKey(io::parseFiniteDouble(r.fields[0], path, r.line, "stamp"))].push_back(b);
  }
  return out;
}

}  // namespace bench
}  // namespace yolo_slam
