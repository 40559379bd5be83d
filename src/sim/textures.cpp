#include "yolo_slam/sim/textures.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <dirent.h>

namespace yolo_slam {
namespace sim {

Texture makeTexture(const std::string& name, const cv::Mat& image) {
  Texture t;
  t.name = name;
  t.levels.push_back(image);
  while (t.levels.back().cols >= 32 && t.levels.back().rows >= 32) {
    cv::Mat down;
    cv::pyrDown(t.levels.back(), down);
    t.levels.push_back(down);
  }
  return t;
}

std::string defaultTextureDir() { return "/usr/share/doc/opencv-doc/examples/data"; }

const std::vector<std::string>& defaultTextureFiles() {
  static const std::vector<std::string> files = {
      "aero1.jpg",    "aero3.jpg",     "aloeL.jpg",       "apple.jpg",
      "baboon.jpg",   "board.jpg",     "box_in_scene.png", "building.jpg",
      "butterfly.jpg", "ela_original.jpg", "fruits.jpg",  "graf1.png",
      "home.jpg",     "left.jpg",      "leuvenA.jpg",     "licenseplate_motion.jpg",
      "orange.jpg",   "rubberwhale1.png", "squirrel_cls.jpg", "starry_night.jpg",
      "stuff.jpg",    "sudoku.png"};
  return files;
}

static bool sameDir(const std::string& a, const std::string& b) {
  auto strip = [](std::string s) {
    while (s.size() > 1 && s.back() == '/') s.pop_back();
    return s;
  };
  return strip(a) == strip(b);
}

std::vector<std::string> listTextureFiles(const std::string& dir) {
  if (!dirExists(dir))
    throw Error("texture folder " + dir +
                " does not exist: pass --textures with a folder of photographs (install "
                "opencv-doc for the default one)");
  std::vector<std::string> out;
  if (sameDir(dir, defaultTextureDir())) {
    for (const auto& f : defaultTextureFiles())
      if (fileExists(joinPath(dir, f))) out.push_back(f);
  } else {
    DIR* d = ::opendir(dir.c_str());
    if (!d) throw Error("cannot list texture folder " + dir + ": check its permissions");
    while (dirent* e = ::readdir(d)) {
      std::string n = e->d_name;
      std::string low = n;
      std::transform(low.begin(), low.end(), low.begin(), ::tolower);
      for (const char* ext : {".jpg", ".jpeg", ".png", ".bmp"}) {
        std::string x(ext);
        if (low.size() > x.size() && low.compare(low.size() - x.size(), x.size(), x) == 0) {
          out.push_back(n);
          break;
        }
      }
    }
    ::closedir(d);
    std::sort(out.begin(), out.end());
  }
  if (out.size() < 4)
    throw Error("texture folder " + dir + " holds " + std::to_string(out.size()) +
                " usable images; at least 4 photographs (.jpg/.png/.bmp) are needed");
  return out;
}

std::vector<Texture> loadTextures(const std::string& dir) {
  std::vector<Texture> out;
  for (const auto& f : listTextureFiles(dir)) {
    std::string path = joinPath(dir, f);
    cv::Mat img = cv::imread(path, cv::IMREAD_COLOR);
    if (img.empty())
      throw Error("cannot read texture image " + path + ": remove it or replace it by a valid image");
    if (img.cols < 128 || img.rows < 128) continue;  // too small to texture a surface
    out.push_back(makeTexture(f, img));
  }
  if (out.size() < 4)
    throw Error("texture folder " + dir + " holds fewer than 4 images of at least 128x128 pixels");
  return out;
}

}  // namespace sim
}  // namespace yolo_slam
