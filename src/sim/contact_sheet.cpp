#include "yolo_slam/sim/contact_sheet.h"

#include <opencv2/imgproc.hpp>

namespace yolo_slam {
namespace sim {

cv::Mat colouriseDepth(const cv::Mat& depth_m, double max_m) {
  cv::Mat d8;
  depth_m.convertTo(d8, CV_8U, 255.0 / max_m);
  cv::Mat c;
  cv::applyColorMap(d8, c, cv::COLORMAP_TURBO);
  c.setTo(cv::Scalar::all(0), depth_m <= 0);
  return c;
}

cv::Mat contactSheet(const SynthOptions& base, const std::vector<std::string>& preset_names,
                     const std::vector<int>& frames, int tile_width) {
  std::vector<cv::Mat> rows;
  for (const auto& name : preset_names) {
    SynthOptions o = base;
    o.preset = name;
    o.frames = 0;
    SequenceGenerator gen(o);
    std::vector<cv::Mat> tiles;  // the frames of one preset side by side
    for (int fi : frames) {
      size_t i = std::min<size_t>((size_t)fi, gen.size() - 1);
      SynthFrame f = gen.frame(i);
      cv::Mat rgb = f.bgr.clone();
      for (const auto& ob : f.objects)
        cv::rectangle(rgb, ob.box, ob.cls == "person" ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 200, 255), 3);
      const std::string label = name + " #" + std::to_string(i);
      cv::putText(rgb, label, cv::Point(10, 34), cv::FONT_HERSHEY_SIMPLEX, 1.1, cv::Scalar(0, 0, 0), 6);
      cv::putText(rgb, label, cv::Point(10, 34), cv::FONT_HERSHEY_SIMPLEX, 1.1, cv::Scalar(255, 255, 255), 2);
      cv::Mat mask;
      cv::cvtColor(f.mask, mask, cv::COLOR_GRAY2BGR);
      for (cv::Mat m : {rgb, colouriseDepth(f.depth), mask}) {
        cv::Mat t;
        cv::resize(m, t, cv::Size(tile_width, tile_width * m.rows / m.cols), 0, 0, cv::INTER_AREA);
        cv::copyMakeBorder(t, t, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar::all(255));
        tiles.push_back(t);
      }
    }
    cv::Mat row;
    cv::hconcat(tiles, row);
    rows.push_back(row);
  }
  cv::Mat sheet;
  cv::vconcat(rows, sheet);
  return sheet;
}

}  // namespace sim
}  // namespace yolo_slam
