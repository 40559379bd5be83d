// Decoding and NMS on hand-made network outputs.
#include "yolo_slam/detection/decode.h"

#include <gtest/gtest.h>

using namespace yolo_slam::detection;

TEST(Decode, LetterboxMapsBackToImagePixels) {
  InputTransform t = InputTransform::make(cv::Size(640, 480), cv::Size(320, 320), true);
  EXPECT_DOUBLE_EQ(t.scale_x, 0.5);
  EXPECT_DOUBLE_EQ(t.scale_y, 0.5);
  EXPECT_DOUBLE_EQ(t.pad_x, 0);
  EXPECT_DOUBLE_EQ(t.pad_y, 40);  // 240 rows of image centred in 320
  cv::Rect2f r = t.toImage(cv::Rect2f(10, 50, 100, 60));
  EXPECT_FLOAT_EQ(r.x, 20);
  EXPECT_FLOAT_EQ(r.y, 20);
  EXPECT_FLOAT_EQ(r.width, 200);
  EXPECT_FLOAT_EQ(r.height, 120);
  cv::Mat fitted = fitToInput(cv::Mat(480, 640, CV_8UC3, cv::Scalar(1, 2, 3)), cv::Size(320, 320), t);
  EXPECT_EQ(fitted.at<cv::Vec3b>(10, 160), cv::Vec3b(114, 114, 114));  // padding band
  EXPECT_EQ(fitted.at<cv::Vec3b>(160, 160), cv::Vec3b(1, 2, 3));

  InputTransform s = InputTransform::make(cv::Size(640, 480), cv::Size(320, 320), false);
  cv::Rect2f q = s.toImage(cv::Rect2f(0, 0, 320, 320));
  EXPECT_FLOAT_EQ(q.width, 640);
  EXPECT_FLOAT_EQ(q.height, 480);
}

TEST(Decode, YoloRowsNormalisedAndPixel) {
  // Two classes; keep only class 1.
  cv::Mat rows = (cv::Mat_<float>(3, 7) <<
      0.5f, 0.5f, 0.25f, 0.5f, 0.9f, 0.1f, 0.8f,    // class 1, kept
      0.2f, 0.2f, 0.1f, 0.1f, 0.9f, 0.85f, 0.0f,    // class 0, not dynamic
      0.7f, 0.7f, 0.1f, 0.1f, 0.2f, 0.0f, 0.1f);    // below threshold
  std::vector<Candidate> out;
  decodeYoloRows(rows, cv::Size(320, 320), true, true, {false, true}, 0.3f, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].class_id, 1);
  EXPECT_FLOAT_EQ(out[0].score, 0.8f);
  EXPECT_FLOAT_EQ(out[0].rect.x, 160 - 40);
  EXPECT_FLOAT_EQ(out[0].rect.y, 160 - 80);
  EXPECT_FLOAT_EQ(out[0].rect.width, 80);

  // YOLOv5-style ONNX rows: pixel coordinates, score = objectness * class score.
  cv::Mat px = (cv::Mat_<float>(1, 7) << 100, 100, 20, 40, 0.5f, 0.0f, 0.9f);
  out.clear();
  decodeYoloRows(px, cv::Size(320, 320), false, false, {false, true}, 0.3f, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FLOAT_EQ(out[0].score, 0.45f);
  EXPECT_FLOAT_EQ(out[0].rect.x, 90);
  EXPECT_FLOAT_EQ(out[0].rect.height, 40);
}

TEST(Decode, NanoDetDistancesAroundCellCentres) {
  // A 64x64 input at stride 32: 2x2 cells, 1 class, 2 bins per side.
  cv::Mat cls = cv::Mat::zeros(4, 1, CV_32F), reg = cv::Mat::zeros(4, 8, CV_32F);
  cls.at<float>(3) = 0.9f;  // cell (x=1, y=1), centre (48, 48)
  // Logits making the distance expectation 1 bin (= 32 px) on every side.
  for (int k = 0; k < 4; ++k) { reg.at<float>(3, 2 * k) = -50.f; reg.at<float>(3, 2 * k + 1) = 50.f; }
  std::vector<Candidate> out;
  decodeNanoDetLevel(cls, reg, 32, cv::Size(64, 64), {true}, 0.5f, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].rect.x, 16, 1e-3);
  EXPECT_NEAR(out[0].rect.y, 16, 1e-3);
  EXPECT_NEAR(out[0].rect.width, 64, 1e-3);
  EXPECT_FLOAT_EQ(out[0].score, 0.9f);
}

TEST(Decode, NmsPerClassAndClipping) {
  std::vector<Candidate> c = {
      {0, 0.9f, cv::Rect2f(10, 10, 100, 100)},
      {0, 0.8f, cv::Rect2f(12, 12, 100, 100)},   // duplicate of the first: suppressed
      {1, 0.7f, cv::Rect2f(12, 12, 100, 100)},   // other class: kept
      {0, 0.6f, cv::Rect2f(250, 250, 100, 100)}, // partly outside a 300x300 image: clipped
  };
  Boxes b = suppressAndMap(c, 0.3f, 0.45f, InputTransform(), cv::Size(300, 300), {"person", "dog"});
  ASSERT_EQ(b.size(), 3u);
  EXPECT_FLOAT_EQ(b[0].score, 0.9f);
  EXPECT_EQ(b[1].label, "dog");
  EXPECT_FLOAT_EQ(b[2].rect.x + b[2].rect.width, 300);
  EXPECT_FLOAT_EQ(b[2].rect.y + b[2].rect.height, 300);
  EXPECT_NEAR(iou(cv::Rect2f(0, 0, 2, 2), cv::Rect2f(1, 0, 2, 2)), 1.f / 3.f, 1e-6);
}
