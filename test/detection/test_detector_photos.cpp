// The detector on real photographs, against person boxes annotated by hand (x1, y1, x2, y2 in
// pixels, read off the images on a 40-50 px grid; the TUM frame's boxes agree with the
// dynamic_mask shipped beside it).
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/detection/decode.h"
#include "yolo_slam/detection/detector.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

using namespace yolo_slam;
using namespace yolo_slam::detection;

namespace {

cv::Rect2f box(float x1, float y1, float x2, float y2) { return {x1, y1, x2 - x1, y2 - y1}; }

const char* kTumFrame = "data/tum/rgbd_dataset_freiburg3_walking_xyz/rgb/1341846313.592026.png";
const char* kTumMask = "data/tum/rgbd_dataset_freiburg3_walking_xyz/dynamic_mask/1341846313.592026.png";

struct Photo {
  const char* path;  // under sharedDir() or absolute
  std::vector<cv::Rect2f> people;
};

std::vector<Photo> photos() {
  return {
      {kTumFrame, {box(50, 120, 240, 478), box(482, 8, 640, 480)}},  // seated man, standing man
      {"data/images/basketball1.png", {box(38, 80, 165, 478), box(436, 20, 640, 480)}},
      {"data/images/person.jpg", {box(190, 98, 275, 372)}},
      {"data/images/bus.jpg",
       {box(50, 398, 245, 902), box(222, 405, 345, 858), box(0, 555, 78, 872),
        box(668, 398, 810, 878)}},
  };
}

cv::Mat load(const std::string& rel) {
  std::string p = rel.front() == '/' ? rel : joinPath(sharedDir(), rel);
  cv::Mat m = cv::imread(p, cv::IMREAD_UNCHANGED);
  EXPECT_FALSE(m.empty()) << p;
  return m;
}

// Every annotated person is matched by a distinct detection with IoU > 0.5.
void expectAllFound(const Boxes& found, const std::vector<cv::Rect2f>& people, float conf,
                    const std::string& what) {
  std::vector<bool> used(found.size(), false);
  for (const auto& p : people) {
    int best = -1;
    float best_iou = 0.5f;
    for (size_t i = 0; i < found.size(); ++i) {
      float v = iou(found[i].rect, p);
      if (!used[i] && v > best_iou) { best = int(i); best_iou = v; }
    }
    ASSERT_GE(best, 0) << what << ": no detection with IoU > 0.5 for person at " << p;
    used[best] = true;
    EXPECT_GE(found[best].score, conf) << what;
    EXPECT_EQ(found[best].label, "person") << what;
  }
}

}  // namespace

TEST(DetectorPhotos, HandAnnotationOfTumFrameAgreesWithMask) {
  cv::Mat mask = load(kTumMask);
  ASSERT_EQ(mask.type(), CV_8UC1);
  cv::Mat labels, stats, centroids;
  int n = cv::connectedComponentsWithStats(mask > 127, labels, stats, centroids);
  std::vector<cv::Rect2f> blobs;
  for (int i = 1; i < n; ++i)
    if (stats.at<int>(i, cv::CC_STAT_AREA) > 1000)
      blobs.emplace_back(cv::Rect(stats.at<int>(i, 0), stats.at<int>(i, 1), stats.at<int>(i, 2),
                                  stats.at<int>(i, 3)));
  ASSERT_EQ(blobs.size(), 2u);
  const auto all = photos();
  for (const auto& p : all[0].people) {
    float best = 0;
    for (const auto& b : blobs) best = std::max(best, iou(p, b));
    EXPECT_GT(best, 0.8f) << p;
  }
}

TEST(DetectorPhotos, DefaultModelFindsEveryPerson) {
  DetectorOptions opt;  // default model, letterbox, conf 0.3
  EXPECT_TRUE(opt.letterbox);
  YoloDetector det(opt);
  for (const auto& ph : photos()) {
    cv::Mat img = load(ph.path);
    Boxes found = det.detect(img);  // basketball1.png is greyscale: converted inside
    for (const auto& b : found) {
      EXPECT_GE(b.rect.x, 0.f);
      EXPECT_GE(b.rect.y, 0.f);
      EXPECT_LE(b.rect.br().x, float(img.cols));
      EXPECT_LE(b.rect.br().y, float(img.rows));
    }
    expectAllFound(found, ph.people, opt.conf_threshold, ph.path);
  }
}

TEST(DetectorPhotos, PlainResizeAlsoFindsEveryPerson) {
  DetectorOptions opt;
  opt.letterbox = false;
  YoloDetector det(opt);
  for (const auto& ph : photos()) expectAllFound(det.detect(load(ph.path)), ph.people, opt.conf_threshold, ph.path);
}

TEST(DetectorPhotos, NoPersonInPhotosWithoutPeople) {
  YoloDetector det{DetectorOptions()};
  // An indoor-free architecture photo with birds, and a still life of fruit (checked by eye).
  for (const char* name : {"home.jpg", "fruits.jpg"}) {
    std::string p = std::string("/usr/share/doc/opencv-doc/examples/data/") + name;
    if (!fileExists(p)) GTEST_SKIP() << p << " missing: install opencv-doc";
    EXPECT_TRUE(det.detect(load(p)).empty()) << p;
  }
}

TEST(DetectorPhotos, OtherSharedModelsFindThePerson) {
  const cv::Mat img = load("data/images/person.jpg");
  const auto person = photos()[2].people;
  struct M { const char* model; const char* cls; };
  for (const M& m : {M{"mnv2-yolov3-nano-coco", "person"}, M{"yolo-fastest-xl-voc", "person"},
                     M{"yolo-fastest-1.1-body", "body"}, M{"nanodet-m/nanodet.onnx", "person"},
                     M{"nanodet-m/nanodet_m.onnx", "person"}}) {
    DetectorOptions opt;
    opt.model = joinPath(sharedDir(), std::string("models/") + m.model);
    opt.dynamic_classes = {m.cls};
    YoloDetector det(opt);
    Boxes found = det.detect(img);
    ASSERT_FALSE(found.empty()) << m.model;
    EXPECT_EQ(found[0].label, m.cls) << m.model;
    EXPECT_GT(iou(found[0].rect, person[0]), 0.5f) << m.model << " " << found[0].rect;
  }
}

TEST(DetectorPhotos, BadInputsAreErrors) {
  YoloDetector det{DetectorOptions()};
  EXPECT_THROW(det.detect(cv::Mat()), Error);
  EXPECT_THROW(det.detect(cv::Mat(48, 64, CV_32FC3, cv::Scalar::all(0))), Error);
  DetectorOptions missing;
  missing.model = "/nonexistent/models/x.cfg";
  EXPECT_THROW(YoloDetector d(missing), Error);
}
