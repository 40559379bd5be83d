#pragma once
// Real photographs used as surface textures of the synthetic room, with a mip pyramid each so
// that far or grazing surfaces are sampled without aliasing.
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace yolo_slam {
namespace sim {

struct Texture {
  std::string name;            // file name (no folder)
  std::vector<cv::Mat> levels; // CV_8UC3 BGR (or CV_8UC4 BGRA for sprites); level k = 1/2^k
  int width() const { return levels.empty() ? 0 : levels[0].cols; }
  int height() const { return levels.empty() ? 0 : levels[0].rows; }
};

// Builds the pyramid (levels down to ~16 px) of an image.
Texture makeTexture(const std::string& name, const cv::Mat& image);

// Folder of the default photographs: opencv-doc's examples/data.
std::string defaultTextureDir();
// The photographs of defaultTextureDir() used by default: real photos without people, skipping
// calibration boards, drawings, text scans and near-duplicates (aloeR, graf3, leuvenB, right,
// rubberwhale2, ela_modified stay unused, e.g. for training a vocabulary on unseen images).
const std::vector<std::string>& defaultTextureFiles();

// The image files a texture folder contributes: for defaultTextureDir() the curated list above,
// for any other folder every .jpg/.jpeg/.png/.bmp in it (sorted by name) of at least 128x128.
// Throws yolo_slam::Error naming the folder when it is missing or holds fewer than 4 images.
std::vector<std::string> listTextureFiles(const std::string& dir);

// Loads the textures of listTextureFiles(dir). Errors name the unreadable file.
std::vector<Texture> loadTextures(const std::string& dir);

}  // namespace sim
}  // namespace yolo_slam
