#pragma once
// Held-out real photographs for the retrieval and matching tests: none of them is in the
// shipped vocabulary's training set (vocab/training_inputs.txt).
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <opencv2/imgcodecs.hpp>

#include <string>
#include <vector>

namespace vocab_test {

inline std::vector<std::string> heldOutImagePaths() {
  const std::string doc = "/usr/share/doc/opencv-doc/examples/data/";  // Debian opencv-doc
  const std::string shared = yolo_slam::joinPath(yolo_slam::sharedDir(), "data");
  return {shared + "/images/bus.jpg", shared + "/images/basketball1.png",
          shared + "/tum/rgbd_dataset_freiburg3_walking_xyz/rgb/1341846313.592026.png",
          doc + "building.jpg", doc + "home.jpg", doc + "baboon.jpg", doc + "fruits.jpg",
          doc + "graf1.png", doc + "aero1.jpg", doc + "box_in_scene.png", doc + "messi5.jpg",
          doc + "leuvenA.jpg", doc + "stuff.jpg", doc + "board.jpg"};
}

inline cv::Mat loadGray(const std::string& path) {
  cv::Mat g = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (g.empty()) throw yolo_slam::Error(path + ": test image missing (install opencv-doc / check ../shared)");
  return g;
}

inline std::shared_ptr<yolo_slam::vocabulary::Vocabulary> shippedVocabulary() {
  return yolo_slam::vocabulary::Vocabulary::load(
      yolo_slam::joinPath(yolo_slam::packageDir(), "vocab/yolo_slam_orb_k10_L4.vocab"));
}

}  // namespace vocab_test
