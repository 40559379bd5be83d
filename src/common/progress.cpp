#include "yolo_slam/common/progress.h"

#include <cstdio>
#include <unistd.h>

namespace yolo_slam {

ProgressBar::ProgressBar(std::string label, size_t total)
    : label_(std::move(label)), total_(total), tty_(::isatty(STDERR_FILENO) == 1) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(size_t done, const std::string& extra) {
  if (!tty_ || total_ == 0) return;
  const int width = 30;
  const double frac = done >= total_ ? 1.0 : static_cast<double>(done) / static_cast<double>(total_);
  const int filled = static_cast<int>(frac * width);
  std::fprintf(stderr, "\r%s [", label_.c_str());
  for (int i = 0; i < width; ++i) std::fputc(i < filled ? '#' : '.', stderr);
  std::fprintf(stderr, "] %zu/%zu %s\033[K", done, total_, extra.c_str());
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (tty_ && !finished_) std::fputc('\n', stderr);
  finished_ = true;
}

}  // namespace yolo_slam
