// Several detection models on one frame (Detector.extraModels): the merge rule on constructed
// boxes, and the default pair of shared models on the real TUM frame with its person mask.
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/detection/decode.h"
#include "yolo_slam/detection/detector.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

using namespace yolo_slam;
using namespace yolo_slam::detection;

namespace {

Box box(float x1, float y1, float x2, float y2, float score, const std::string& label) {
  Box b;
  b.rect = cv::Rect2f(x1, y1, x2 - x1, y2 - y1);
  b.score = score;
  b.label = label;
  return b;
}

const char* kTumFrame = "data/tum/rgbd_dataset_freiburg3_walking_xyz/rgb/1341846313.592026.png";
const char* kTumMask = "data/tum/rgbd_dataset_freiburg3_walking_xyz/dynamic_mask/1341846313.592026.png";

// Share of the mask's pixels inside at least one box.
double maskCovered(const cv::Mat& mask, const Boxes& boxes) {
  cv::Mat covered = cv::Mat::zeros(mask.size(), CV_8U);
  for (const auto& b : boxes) covered(cv::Rect(b.rect) & cv::Rect(0, 0, mask.cols, mask.rows)) = 255;
  return double(cv::countNonZero(covered & (mask > 127))) / cv::countNonZero(mask > 127);
}

}  // namespace

TEST(MergeOverlapping, OnePersonTwoBoxesBecomeTheEnclosingBox) {
  Boxes in = {box(100, 50, 200, 400, 0.7f, "body"),     // same person as the next, lower score
              box(110, 40, 190, 380, 0.9f, "person"),
              box(400, 60, 500, 420, 0.6f, "person"),   // another person, no overlap
              box(150, 300, 260, 470, 0.5f, "body")};   // touches the first person (IoU < 0.45)
  Boxes out = mergeOverlapping(in, 0.45f);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].label, "person");  // the higher score leads and names the merged box
  EXPECT_FLOAT_EQ(out[0].score, 0.9f);
  EXPECT_EQ(out[0].rect, cv::Rect2f(100, 40, 100, 360));
  EXPECT_EQ(out[1].rect, in[2].rect);
  EXPECT_EQ(out[2].rect, in[3].rect);
  EXPECT_TRUE(mergeOverlapping({}, 0.45f).empty());
}

// Crowd seed 1, frame 7: the extra model's box of two people side by side grows the main
// model's box of the right one; the main model's box of the left one overlaps the grown box by
// IoU 0.5 but the right one's own box by 0.25: two people, two boxes.
TEST(MergeOverlapping, AGrownBoxDoesNotSwallowTheNeighbour) {
  const Boxes in = {box(420, 26, 640, 480, 0.99f, "person"),   // the right person
                    box(341, 50, 640, 471, 0.85f, "body"),     // both of them, the other model
                    box(330, 38, 499, 479, 0.31f, "person")};  // the left person
  const Boxes out = mergeOverlapping(in, 0.45f);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].rect, cv::Rect2f(341, 26, 299, 454));
  EXPECT_EQ(out[1].rect, in[2].rect);
}

TEST(MultiModelDetector, DefaultPairCoversMoreOfTheRealPeople) {
  const cv::Mat img = cv::imread(joinPath(sharedDir(), kTumFrame));
  const cv::Mat mask = cv::imread(joinPath(sharedDir(), kTumMask), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(img.empty());
  ASSERT_FALSE(mask.empty());
  DetectorOptions opt;
  ASSERT_FALSE(opt.extra_models.empty());
  std::unique_ptr<Detector> both = makeDetector(opt);
  EXPECT_NE(both->description().find("yolo-fastest-1.1_body.cfg"), std::string::npos) << both->description();
  DetectorOptions alone = opt;
  alone.extra_models.clear();
  std::unique_ptr<Detector> main = makeDetector(alone);
  EXPECT_EQ(main->description().find("yolo-fastest-1.1_body.cfg"), std::string::npos);

  const Boxes b = both->detect(img), m = main->detect(img);
  ASSERT_EQ(b.size(), 2u);  // the seated and the standing man, each boxed once
  ASSERT_EQ(m.size(), 2u);
  for (size_t i = 0; i < b.size(); ++i) EXPECT_GE(b[i].score, b[std::min(i + 1, b.size() - 1)].score);
  const double cov_both = maskCovered(mask, b), cov_main = maskCovered(mask, m);
  EXPECT_GT(cov_both, cov_main);  // the merged boxes enclose both models' boxes
  EXPECT_GT(cov_both, 0.96);
}

TEST(MultiModelDetector, MissingExtraModelNamesTheKey) {
  DetectorOptions opt;
  opt.extra_models = {"/nonexistent/extra.cfg"};
  try {
    MultiModelDetector d(opt);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/nonexistent/extra.cfg"), std::string::npos) << what;
    EXPECT_NE(what.find("Detector.extraModels"), std::string::npos) << what;
  }
}
