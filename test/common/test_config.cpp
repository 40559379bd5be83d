#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/timing.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <unistd.h>

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

TEST(Config, OverridesWinOverTheFileAndKeepTheirTypes) {
  Config c = Config::fromString("Screening.mode: \"detect\"\nORBextractor.nFeatures: 1000\n", "s.yaml");
  c.setFromAssignment("Screening.mode=off");
  c.set("ORBextractor.nFeatures", "500");
  c.set("Detector.extraModels", "[a, b]");
  c.setFromAssignment("Screening.boxDilation=0.1");
  EXPECT_EQ(c.getString("Screening.mode", ""), "off");
  EXPECT_EQ(c.getInt("ORBextractor.nFeatures", 0), 500);
  EXPECT_EQ(c.getStringList("Detector.extraModels", {}), (std::vector<std::string>{"a", "b"}));
  EXPECT_DOUBLE_EQ(c.getDouble("Screening.boxDilation", 0.05), 0.1);
  EXPECT_TRUE(c.has("Screening.boxDilation"));
  EXPECT_EQ(c.overrides().size(), 4u);
  // A wrong type is still an error naming the key.
  c.set("ORBextractor.nFeatures", "many");
  EXPECT_THROW(c.getInt("ORBextractor.nFeatures", 0), Error);
  EXPECT_THROW(c.setFromAssignment("no-equals-sign"), Error);
  EXPECT_THROW(c.set("", "1"), Error);
}

TEST(Config, EffectiveRecordsWhatEveryGetterReturned) {
  Config c = Config::fromString("Camera.fx: 535.4\nUnread.key: 3\n");
  const Config copy = c;  // copies share the record
  c.getDouble("Camera.fx", 0);
  copy.getInt("Absent.key", 7);
  c.getBool("Flag", true);
  c.getString("Name", "x");
  const Json e = c.effective();
  EXPECT_DOUBLE_EQ(e["Camera.fx"].get<double>(), 535.4);
  EXPECT_EQ(e["Absent.key"], 7);
  EXPECT_EQ(e["Flag"], true);
  EXPECT_EQ(e["Name"], "x");
  EXPECT_FALSE(e.contains("Unread.key"));
  EXPECT_EQ(copy.effective(), e);
}

namespace {

// The message of the yolo_slam::Error `f` throws ("" and a test failure when it throws none).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a yolo_slam::Error";
  return "";
}

const char* kCamera = "Camera.fx: 535.4\nCamera.fy: 539.2\nCamera.cx: 320.1\nCamera.cy: 247.6\n";

}  // namespace

TEST(Config, YamlErrorNamesTheLine) {
  char path[] = "/tmp/ys_truncated_XXXXXX.yaml";
  const int fd = ::mkstemps(path, 5);
  ASSERT_GE(fd, 0);
  const std::string text = "%YAML:1.0\nCamera.fx: 535.4\nCamera.fy: 539.2\nCamera.cx 320.1\n";
  ASSERT_EQ(::write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  ::close(fd);
  const std::string msg = errorOf([&] { Config::fromFile(path); });
  std::remove(path);
  EXPECT_NE(msg.find(std::string(path) + ":4: malformed YAML (Missing ':')"), std::string::npos) << msg;
  EXPECT_NE(msg.find("fix line 4"), std::string::npos) << msg;
}

TEST(Config, IntegerOutOfRangeSaysSo) {
  const Config c = Config::fromString("ORBextractor.nFeatures: 1e10\nORBextractor.nLevels: 2.5\n", "r.yaml");
  const std::string big = errorOf([&] { c.getInt("ORBextractor.nFeatures", 0); });
  EXPECT_NE(big.find("r.yaml: key 'ORBextractor.nFeatures' is out of range (got 10000000000"), std::string::npos) << big;
  const std::string frac = errorOf([&] { c.getInt("ORBextractor.nLevels", 0); });
  EXPECT_NE(frac.find("must be an integer (got 2.5)"), std::string::npos) << frac;
}

TEST(Config, UnknownKeysWarnWithTheNearestKnownKey) {
  const Config c = Config::fromString("Camera.fx: 535.4\nORBextractor.nFeaturez: 1500\nViewer.PointSize: 2\n", "typo.yaml");
  ASSERT_EQ(c.warnings().size(), 1u) << "Viewer.* of ORB-SLAM2 files is accepted";
  const std::string& w = c.warnings()[0];
  // fromString puts "%YAML:1.0" in front: the key is on line 3 of that text.
  EXPECT_NE(w.find("typo.yaml:3: unknown key 'ORBextractor.nFeaturez' is ignored; did you mean "
                   "'ORBextractor.nFeatures'?"),
            std::string::npos)
      << w;
  Config o;
  o.set("screening.Mode", "off");
  ASSERT_EQ(o.warnings().size(), 1u);
  EXPECT_NE(o.warnings()[0].find("did you mean 'Screening.mode'"), std::string::npos) << o.warnings()[0];
  EXPECT_TRUE(Config::fromString(kCamera).warnings().empty());
}

TEST(Config, ShippedFilesHaveNoUnknownKey) {
  for (const char* name : {"TUM1.yaml", "TUM2.yaml", "TUM3.yaml"})
    EXPECT_TRUE(Config::fromFile(joinPath(packageDir(), std::string("config/") + name)).warnings().empty()) << name;
}

TEST(Config, CameraRejectsNanAndAbsurdValuesNamingFileAndKey) {
  const std::pair<const char*, const char*> cases[] = {
      {"Camera.cx", ".nan"},       {"Camera.cy", "1e9"},       {"Camera.cx", "-3"},
      {"Camera.fx", ".inf"},       {"Camera.k1", ".nan"},      {"Camera.width", "1e10"},
      {"Camera.height", "100000"}, {"DepthMaxRange", "0"},     {"Camera.bf", ".nan"},
      {"ThDepth", "-1"},
  };
  for (const auto& [key, value] : cases) {
    Config c = Config::fromString(kCamera, "cam.yaml");
    c.set(key, value);
    const std::string msg = errorOf([&] { CameraModel::load(c); });
    EXPECT_NE(msg.find(std::string("cam.yaml: key '") + key + "'"), std::string::npos) << key << msg;
  }
  const CameraModel cam = CameraModel::load(Config::fromString(std::string(kCamera) + "DepthMaxRange: 6\n"));
  EXPECT_DOUBLE_EQ(cam.max_depth, 6.0);
}
