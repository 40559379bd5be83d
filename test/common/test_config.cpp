#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/timing.h"

#include <gtest/gtest.h>

using namespace yolo_slam;

TEST(Config, ReadsOrbSlamStyleKeys) {
  Config c = Config::fromString(
      "Camera.fx: 535.4\nCamera.fy: 539.2\nCamera.cx: 320.1\nCamera.cy: 247.6\n"
      "Camera.bf: 40.0\nThDepth: 40.0\nDepthMapFactor: 5000.0\nORBextractor.nFeatures: 1000\n");
  CameraModel cam = CameraModel::load(c);
  EXPECT_DOUBLE_EQ(cam.fx, 535.4);
  EXPECT_DOUBLE_EQ(cam.cy, 247.6);
  EXPECT_DOUBLE_EQ(cam.depth_map_factor, 5000.0);
  EXPECT_EQ(c.getInt("ORBextractor.nFeatures", 0), 1000);
  EXPECT_EQ(c.getInt("Missing.key", 7), 7);
  EXPECT_NEAR(cam.closeDepth(), 40.0 * 40.0 / 535.4, 1e-12);
}

TEST(Config, MissingRequiredKeyNamesKey) {
  Config c = Config::fromString("Camera.fx: 535.4\n", "cam.yaml");
  try {
    CameraModel::load(c);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cam.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("Camera.fy"), std::string::npos);
  }
}

TEST(Config, TruncatedYamlIsAnErrorNamingTheFile) {
  EXPECT_THROW(Config::fromString("Camera.fx: [535.4, \n  Camera", "trunc.yaml"), Error);
  EXPECT_THROW(Config::fromFile("/nonexistent/settings.yaml"), Error);
}

TEST(Config, WrongTypeIsAnError) {
  Config c = Config::fromString("Camera.fx: abc\n", "t.yaml");
  EXPECT_THROW(c.getDouble("Camera.fx", 1.0), Error);
}

TEST(Config, ShippedTumFilesLoad) {
  for (const char* name : {"TUM1.yaml", "TUM2.yaml", "TUM3.yaml"}) {
    CameraModel cam = CameraModel::load(Config::fromFile(joinPath(packageDir(), std::string("config/") + name)));
    EXPECT_GT(cam.fx, 500.0) << name;
  }
}

TEST(Timing, SummaryMedianAndP95) {
  Summary s = summarize({5, 1, 3, 2, 4});
  EXPECT_DOUBLE_EQ(s.median, 3);
  EXPECT_DOUBLE_EQ(s.mean, 3);
  EXPECT_DOUBLE_EQ(s.p95, 5);
  EXPECT_EQ(summarize({}).count, 0u);
}
