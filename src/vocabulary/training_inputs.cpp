#include "yolo_slam/vocabulary/training_inputs.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <dirent.h>
#include <fstream>
#include <map>
#include <random>

namespace yolo_slam {
namespace vocabulary {

namespace {

std::string lowerExt(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string e = path.substr(dot + 1);
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

std::string dirName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

void addVideoFrames(const std::string& path, const InputOptions& opt, std::vector<TrainingItem>& out) {
  cv::VideoCapture cap(path);
  if (!cap.isOpened()) throw Error(path + ": cannot open video (unsupported codec or corrupt file)");
  const int step = std::max(1, opt.video_step);
  int taken = 0;
  cv::Mat frame;
  // Count by decoding: CAP_PROP_FRAME_COUNT is unreliable for some containers.
  for (int i = 0; cap.read(frame); ++i) {
    if (i % step != 0) continue;
    out.push_back({path, i});
    ++taken;
    if (opt.max_video_frames > 0 && taken >= opt.max_video_frames) break;
  }
  if (taken == 0) throw Error(path + ": video has no readable frames");
}

void addInput(const std::string& input, const InputOptions& opt, std::vector<TrainingItem>& out,
              const std::string& where) {
  if (dirExists(input)) {
    std::vector<std::string> files;
    if (DIR* d = ::opendir(input.c_str())) {
      while (dirent* e = ::readdir(d)) {
        const std::string p = joinPath(input, e->d_name);
        if (isImagePath(p) && fileExists(p)) files.push_back(p);
      }
      ::closedir(d);
    }
    if (files.empty()) throw Error(where + input + ": folder holds no images (jpg/jpeg/png/bmp/ppm/pgm/tif)");
    std::sort(files.begin(), files.end());
    for (const auto& f : files) out.push_back({f, -1});
    return;
  }
  if (!fileExists(input))
    throw Error(where + input + ": no such file or folder (inputs are image folders, image lists .txt, videos or images)");
  if (isVideoPath(input)) {
    addVideoFrames(input, opt, out);
  } else if (isImagePath(input)) {
    out.push_back({input, -1});
  } else if (lowerExt(input) == "txt" || lowerExt(input) == "lst") {
    std::ifstream in(input);
    if (!in) throw Error(input + ": cannot read image list");
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
      const size_t hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      const size_t b = line.find_first_not_of(" \t\r");
      if (b == std::string::npos) continue;
      const size_t e = line.find_last_not_of(" \t\r");
      const std::string entry = line.substr(b, e - b + 1);
      const std::string resolved = entry.front() == '/' ? entry : joinPath(dirName(input), entry);
      addInput(resolved, opt, out, input + ":" + std::to_string(n) + ": ");
    }
  } else {
    throw Error(where + input + ": unknown input kind (expected a folder, .txt list, video or image)");
  }
}

}  // namespace

bool isVideoPath(const std::string& path) {
  static const char* kExt[] = {"avi", "mp4", "mkv", "mov", "mpg", "mpeg", "webm", "m4v"};
  const std::string e = lowerExt(path);
  return std::find(std::begin(kExt), std::end(kExt), e) != std::end(kExt);
}

bool isImagePath(const std::string& path) {
  static const char* kExt[] = {"jpg", "jpeg", "png", "bmp", "ppm", "pgm", "tif", "tiff", "webp"};
  const std::string e = lowerExt(path);
  return std::find(std::begin(kExt), std::end(kExt), e) != std::end(kExt);
}

std::vector<TrainingItem> expandInputs(const std::vector<std::string>& inputs, const InputOptions& opt) {
  std::vector<TrainingItem> out;
  for (const auto& in : inputs) addInput(in, opt, out, "");
  return out;
}

std::vector<cv::Mat> loadGrayImages(const std::vector<TrainingItem>& items) {
  std::vector<cv::Mat> out(items.size());
  std::map<std::string, std::vector<size_t>> video_items;
  for (size_t i = 0; i < items.size(); ++i) {
    if (items[i].frame >= 0) {
      video_items[items[i].path].push_back(i);
      continue;
    }
    cv::Mat img = cv::imread(items[i].path, cv::IMREAD_GRAYSCALE);
    if (img.empty()) throw Error(items[i].path + ": cannot decode image (corrupt or unsupported format)");
    out[i] = img;
  }
  for (const auto& v : video_items) {
    cv::VideoCapture cap(v.first);
    if (!cap.isOpened()) throw Error(v.first + ": cannot open video");
    std::map<int, std::vector<size_t>> wanted;
    int last = -1;
    for (size_t i : v.second) {
      wanted[items[i].frame].push_back(i);
      last = std::max(last, items[i].frame);
    }
    cv::Mat frame;
    for (int f = 0; f <= last; ++f) {
      if (!cap.read(frame)) throw Error(v.first + ": frame " + std::to_string(f) + " cannot be read");
      auto it = wanted.find(f);
      if (it == wanted.end()) continue;
      cv::Mat gray;
      if (frame.channels() == 3) cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
      else if (frame.channels() == 4) cv::cvtColor(frame, gray, cv::COLOR_BGRA2GRAY);
      else gray = frame.clone();
      for (size_t i : it->second) out[i] = gray;
    }
  }
  return out;
}

cv::Mat syntheticViewChange(const cv::Mat& gray, uint64_t seed, double strength, cv::Mat* H_out) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double w = gray.cols, h = gray.rows;
  const cv::Point2f c(static_cast<float>(w / 2), static_cast<float>(h / 2));
  // Similarity (rotation + scale about the centre), then a perspective jitter of the corners.
  const double angle = u(rng) * 10.0 * strength;
  const double scale = 1.0 + u(rng) * 0.15 * strength;
  cv::Mat S = cv::getRotationMatrix2D(c, angle, scale);
  cv::Mat S3 = cv::Mat::eye(3, 3, CV_64F);
  S.copyTo(S3.rowRange(0, 2));
  std::vector<cv::Point2f> src{{0, 0}, {float(w), 0}, {float(w), float(h)}, {0, float(h)}}, dst;
  for (const auto& p : src)
    dst.emplace_back(static_cast<float>(p.x + u(rng) * 0.08 * strength * w),
                     static_cast<float>(p.y + u(rng) * 0.08 * strength * h));
  cv::Mat P = cv::getPerspectiveTransform(src, dst);
  cv::Mat H = P * S3;
  if (H_out) *H_out = H.clone();
  cv::Mat out;
  cv::warpPerspective(gray, out, H, gray.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  const double gain = 1.0 + u(rng) * 0.2 * strength;
  const double bias = u(rng) * 0.2 * strength * 128.0;
  out.convertTo(out, CV_8U, gain, bias);
  return out;
}

}  // namespace vocabulary
}  // namespace yolo_slam
