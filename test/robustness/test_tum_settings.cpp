// scripts/tum_settings.py (tum_bag.launch tum:=auto): a TUM camera's intrinsics pick its settings
// file, the ROS default intrinsics of the official bags are resolved by the bag's name, and an
// unknown camera fails naming its intrinsics. Runs in the repository root (the tests' directory).
#include "shell.h"

#include <gtest/gtest.h>

#include <string>

namespace {

using Result = robustness::ShellResult;

Result tumSettings(const std::string& args) {
  return robustness::shell("/usr/bin/python3 scripts/tum_settings.py " + args);
}

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

}  // namespace

TEST(TumSettings, CalibratedIntrinsicsPickTheirFile) {
  const Result fr1 = tumSettings("--intrinsics 517.3 516.5 318.6 255.3");
  EXPECT_EQ(fr1.exit_code, 0) << fr1.out;
  EXPECT_TRUE(endsWith(fr1.out, "config/TUM1.yaml")) << fr1.out;
  const Result fr3 = tumSettings("--intrinsics 535.4 539.2 320.1 247.6");
  EXPECT_EQ(fr3.exit_code, 0) << fr3.out;
  EXPECT_TRUE(endsWith(fr3.out, "config/TUM3.yaml")) << fr3.out;
}

TEST(TumSettings, RosDefaultIntrinsicsUseTheBagName) {
  const Result r = tumSettings("--intrinsics 525 525 319.5 239.5 --name rgbd_dataset_freiburg2_xyz.bag");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_TRUE(endsWith(r.out, "config/TUM2.yaml")) << r.out;
}

TEST(TumSettings, UnknownCameraFailsNamingItsIntrinsics) {
  const Result r = tumSettings("--intrinsics 600 601 320 240 --name office.bag");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("fx 600.0 fy 601.0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("settings:="), std::string::npos) << r.out;
}
