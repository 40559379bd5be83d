#pragma once
#include <cstddef>
#include <string>

namespace yolo_slam {

// A one-line progress bar on stderr, drawn only when stderr is a terminal (CI logs stay clean).
class ProgressBar {
 public:
  ProgressBar(std::string label, size_t total);
  ~ProgressBar();
  void update(size_t done, const std::string& extra = "");
  void finish();

 private:
  std::string label_;
  size_t total_;
  bool tty_;
  bool finished_ = false;
};

}  // namespace yolo_slam
