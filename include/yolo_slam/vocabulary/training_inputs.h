#pragma once
// Training inputs for yolo_slam_train_vocab and the retrieval benchmark: image folders, image
// lists and videos expanded into a deterministic list of grey images, plus the synthetic
// viewpoint change used to evaluate retrieval.
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace yolo_slam {
namespace vocabulary {

struct TrainingItem {
  std::string path;
  int frame = -1;  // video frame index, -1 for a still image
  std::string label() const { return frame < 0 ? path : path + "#" + std::to_string(frame); }
};

struct InputOptions {
  int video_step = 10;        // take every n-th video frame
  int max_video_frames = 0;   // per video, 0 = no limit
};

bool isVideoPath(const std::string& path);
bool isImagePath(const std::string& path);

// Expands folders (their image files, sorted by name, not recursive), lists (.txt: one path per
// line, relative to the list's folder, '#' comments; entries may be images or videos), videos
// and single images. Throws yolo_slam::Error naming the input (and list line) if something is
// missing, unreadable or of an unknown kind, or if a folder holds no images.
std::vector<TrainingItem> expandInputs(const std::vector<std::string>& inputs, const InputOptions& options);

// Loads the items as 8-bit grey images, in order (videos are read once each, sequentially).
// Throws yolo_slam::Error naming the file if it cannot be decoded.
std::vector<cv::Mat> loadGrayImages(const std::vector<TrainingItem>& items);

// A small random change of viewpoint for retrieval tests: perspective warp (corner jitter of
// up to `strength` x 8% of the size), rotation up to strength x 10 degrees, scale within
// 1 +- strength x 0.15, brightness/contrast change up to strength x 20%. Deterministic in seed.
// H_out (optional) receives the 3x3 CV_64F homography mapping input to output pixels.
cv::Mat syntheticViewChange(const cv::Mat& gray, uint64_t seed, double strength = 1.0,
                            cv::Mat* H_out = nullptr);

}  // namespace vocabulary
}  // namespace yolo_slam
