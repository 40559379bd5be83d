// The list of known settings keys (common/settings_keys.h), which the YAML loader checks files
// and overrides against, equals what the options loaders read: every key a loader reads is in
// it, every key of config/TUM*.yaml is in it, and every listed key is read by some loader.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/settings_keys.h"
#include "yolo_slam/detection/async_detector.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/system.h"

#include <gtest/gtest.h>

#include <set>

using namespace yolo_slam;

namespace {

// Every key some loader reads, with the settings of a camera (its keys are required) and the
// keys read only when present.
std::set<std::string> keysTheLoadersRead() {
  const Config cfg = Config::fromString(
      "Camera.fx: 535.4\nCamera.fy: 539.2\nCamera.cx: 320.1\nCamera.cy: 247.6\nDetector.extraModels: [ \"\" ]\n");
  CameraModel::load(cfg);
  slam::SystemOptions::load(cfg);
  detection::DetectorOptions::load(cfg);
  detection::AsyncDetectionOptions::load(cfg);
  sim::SynthOptions::load(cfg);
  std::set<std::string> keys;
  const Json effective = cfg.effective();
  for (const auto& kv : effective.items()) keys.insert(kv.key());
  return keys;
}

}  // namespace

TEST(SettingsKeys, TheListIsWhatTheLoadersRead) {
  const std::set<std::string> read = keysTheLoadersRead();
  const std::set<std::string> listed(knownSettingsKeys().begin(), knownSettingsKeys().end());
  for (const std::string& k : read) EXPECT_TRUE(listed.count(k)) << k << " is read but not in settings_keys.cpp";
  for (const std::string& k : listed) EXPECT_TRUE(read.count(k)) << k << " is listed but no loader reads it";
  EXPECT_EQ(listed.size(), knownSettingsKeys().size()) << "a key is listed twice";
}

TEST(SettingsKeys, ShippedFilesUseOnlyKnownKeys) {
  for (const char* name : {"TUM1.yaml", "TUM2.yaml", "TUM3.yaml"}) {
    const Config cfg = Config::fromFile(joinPath(packageDir(), std::string("config/") + name));
    EXPECT_TRUE(cfg.warnings().empty()) << name << ": " << (cfg.warnings().empty() ? "" : cfg.warnings()[0]);
  }
}

TEST(SettingsKeys, NearestKeyFindsTypos) {
  EXPECT_EQ(nearestSettingsKey("ORBextractor.nFeaturez"), "ORBextractor.nFeatures");
  EXPECT_EQ(nearestSettingsKey("camera.FX"), "Camera.fx");
  EXPECT_EQ(nearestSettingsKey("Screening.boxdilation"), "Screening.boxDilation");
  EXPECT_TRUE(isKnownSettingsKey("Viewer.PointSize"));
  EXPECT_FALSE(isKnownSettingsKey("Camera.fxx"));
}
