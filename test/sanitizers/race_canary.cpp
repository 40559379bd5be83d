// Two deliberate data races between our own threads, built and run by scripts/sanitize.sh under
// TSan with test/sanitizers/tsan.supp in force. Both must be reported: the suppressions are for
// uninstrumented libraries only and must not hide races in our code, in particular not a race
// on cv::Mat pixels (heap memory allocated inside libopencv_core, the usual case in the SLAM).
#include <opencv2/core.hpp>

#include <cstdio>
#include <thread>

namespace {
// Incremented by two threads without a lock.
int g_counter = 0;
}  // namespace

int main() {
  // Race 1: a plain global.
  std::thread c1([] { ++g_counter; }), c2([] { ++g_counter; });
  c1.join();
  c2.join();
  // Race 2: cv::Mat pixels written by two threads without a lock.
  cv::Mat image(1, 64, CV_8U, cv::Scalar(0));
  auto paint = [&image](int v) { image.setTo(cv::Scalar(0)), image.at<unsigned char>(0, 7) = static_cast<unsigned char>(v); };
  std::thread p1(paint, 1), p2(paint, 2);
  p1.join();
  p2.join();
  std::printf("counter %d, pixel %d\n", g_counter, image.at<unsigned char>(0, 7));
  return 0;
}
