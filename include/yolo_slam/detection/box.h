#pragma once
#include <opencv2/core/types.hpp>

#include <string>
#include <vector>

namespace yolo_slam {
namespace detection {

// One detected object: class from the model's names file, score in [0,1], pixel box clipped
// to the image (x, y = top-left corner; width, height in pixels).
struct Box {
  int class_id = -1;
  std::string label;
  float score = 0.f;
  cv::Rect2f rect;
  // True for a box screening::BoxTracker carried over from earlier detections (the detector
  // missed the object in this frame); score is then the score of the last detection.
  bool tracked = false;
  // Asynchronous detection: seconds from the image the detector saw to the frame this box is
  // screened in (detection::BoxFeed sets it; 0: the detector saw this frame). The box is where
  // the object was then; screening::BoxTracker moves it to where the object is now.
  double age_s = 0;
};
using Boxes = std::vector<Box>;

}  // namespace detection
}  // namespace yolo_slam
