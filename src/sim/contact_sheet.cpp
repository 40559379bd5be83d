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
    for (int fi : frames) {
      size_t i = std::min<size_t>((size_t)fi, gen.size() - 1);
      SynthFrame f = gen.frame(i);
      cv::Mat rgb = f.bgr.clone();
      for (const auto& ob : f.objects)
        cv::rectangle(rgb, ob.box, ob.cls == "person" ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 200, 255), 2);
      cv::Mat mask;
      cv::cvtColor(f.mask, mask, cv::COLOR_GRAY2BGR);
      cv::Mat row;
      cv::hconcat(std::vector<cv::Mat>{rgb, colouriseDepth(f.depth), mask}, row);
      cv::putText(row, name + " #" + std::to_string(i), cv::Point(8, 24), cv::FONT_HERSHEY_SIMPLEX, 0.8,
                  cv::Scalar(0, 0, 0), 4);
      cv::putText(row, name + " #" + std::to_string(i), cv::Point(8, 24), cv::FONT_HERSHEY_SIMPLEX, 0.8,
                  cv::Scalar(255, 255, 255), 2);
      double s = 3.0 * tile_width / row.cols;
      cv::resize(row, row, cv::Size(), s, s, cv::INTER_AREA);
      rows.push_back(row);
    }
  }
  cv::Mat sheet;
  cv::vconcat(rows, sheet);
  return sheet;
}

}  // namespace sim
}  // namespace yolo_slam
