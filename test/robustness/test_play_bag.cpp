// scripts/play_bag.py (tum_bag.launch's player): a bag that cannot feed the graph ends the launch
// with the file and the fix, before rosbag play starts. Runs in the repository root (the tests'
// directory); the bags are written with the rosbag Python module, and those tests skip without it.
#include "shell.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using robustness::shell;
using Result = robustness::ShellResult;

Result playBag(const std::string& args) { return shell("/usr/bin/python3 scripts/play_bag.py " + args); }

bool haveRosbag() { return shell("/usr/bin/python3 -c 'import rosbag'").exit_code == 0; }

// A bag with three 2x2 colour images on `topic`; `cut` keeps only the first half of the file.
void writeBag(const fs::path& path, const std::string& topic, bool cut = false) {
  const std::string py =
      "import rosbag, rospy, sys\n"
      "from sensor_msgs.msg import Image\n"
      "b = rosbag.Bag(sys.argv[1], 'w')\n"
      "for i in range(3):\n"
      "    m = Image(height=2, width=2, encoding='rgb8', step=6, data=bytes(12))\n"
      "    b.write(sys.argv[2], m, rospy.Time(1 + i))\n"
      "b.close()\n"
      "if sys.argv[3] == '1':\n"
      "    d = open(sys.argv[1], 'rb').read()\n"
      "    open(sys.argv[1], 'wb').write(d[:len(d) // 2])\n";
  const fs::path script = path.string() + ".py";
  std::ofstream(script) << py;
  const Result r = shell("/usr/bin/python3 " + script.string() + " " + path.string() + " " + topic + " " +
                         (cut ? "1" : "0"));
  ASSERT_EQ(r.exit_code, 0) << r.out;
}

class PlayBag : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("ys_play_bag_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

}  // namespace

TEST_F(PlayBag, MissingBagNamesTheFileAndTheConverter) {
  const std::string bag = (dir_ / "nowhere.bag").string();
  const Result r = playBag(bag + " --require /camera/rgb/image_color -- --clock");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find(bag + " does not exist"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("scripts/tum_to_bag.py"), std::string::npos) << r.out;
}

TEST_F(PlayBag, ADirectoryOrGarbageIsRefused) {
  EXPECT_EQ(playBag(dir_.string() + " --require /a").exit_code, 2);
  if (!haveRosbag()) GTEST_SKIP() << "no rosbag Python module";
  const fs::path garbage = dir_ / "garbage.bag";
  std::ofstream(garbage) << "not a bag\n";
  const Result r = playBag(garbage.string() + " --require /a");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("not a readable bag"), std::string::npos) << r.out;
}

TEST_F(PlayBag, OtherImageTopicsAreListedWithTheLaunchArguments) {
  if (!haveRosbag()) GTEST_SKIP() << "no rosbag Python module";
  const fs::path bag = dir_ / "openni2.bag";
  writeBag(bag, "/camera/rgb/image_raw");
  const Result r = playBag(bag.string() + " --require /camera/rgb/image_color --require /camera/depth/image");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("no messages on /camera/rgb/image_color, /camera/depth/image"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("its image topics: /camera/rgb/image_raw"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rgb_topic:="), std::string::npos) << r.out;
}

TEST_F(PlayBag, ACutOffRecordingAsksForReindex) {
  if (!haveRosbag()) GTEST_SKIP() << "no rosbag Python module";
  const fs::path bag = dir_ / "cut.bag";
  writeBag(bag, "/camera/rgb/image_raw", /*cut=*/true);
  const Result r = playBag(bag.string() + " --require /camera/rgb/image_raw");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("rosbag reindex " + bag.string()), std::string::npos) << r.out;
}

TEST_F(PlayBag, ABagWithTheTopicsPassesTheCheck) {
  if (!haveRosbag()) GTEST_SKIP() << "no rosbag Python module";
  const fs::path bag = dir_ / "good.bag";
  writeBag(bag, "/camera/rgb/image_raw");
  const Result r = playBag(bag.string() + " --require /camera/rgb/image_raw --check-only");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("carries /camera/rgb/image_raw"), std::string::npos) << r.out;
}
