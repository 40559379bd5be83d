// Map files (slam/map_file.h): a map of the first frames of a synthetic static_xyz run is
// saved, loaded and saved again (identical bytes, same map), bad files (missing, truncated,
// corrupted, another version, vocabulary, camera or ORB pyramid) are refused with an error
// naming the file while the running map stays as it was, and a new System in
// localization mode relocalises in a loaded map and tracks later frames of the run.
#include "support/bytes.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_file.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/slam/system.h"
#include "yolo_slam/vocabulary/keyframe_database.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include "support/temp_dir.h"
#include "support/loop_preset.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

using namespace yolo_slam;

namespace {

constexpr size_t kMappedFrames = 80;           // frames 0..79 build the map
constexpr size_t kLaterFirst = 80, kLaterLast = 110;  // frames fed to the loaded map
constexpr size_t kFramesBeforeBadLoad = 5;     // a system with a map of its own
constexpr double kMaxPoseError = 0.05;         // metres, relocalised pose against ground truth
constexpr int kOtherPyramidLevels = 6;         // the map is built with the default 8
// Portable binary header: 1 byte endianness flag, 8 bytes magic, then the 4-byte version.
constexpr size_t kVersionOffset = 9;

slam::SystemOptions testOptions() {
  slam::SystemOptions o = slam::SystemOptions::load(Config());
  o.screening.mode = screening::DynamicMode::Off;
  o.slam.loop.enabled = false;
  o.sequential = true;
  return o;
}

sim::SequenceGenerator& generator() {
  static sim::SequenceGenerator gen([] {
    sim::SynthOptions so;
    so.preset = "static_xyz";
    so.frames = static_cast<int>(kLaterLast + 1);
    so.seed = 5;
    return so;
  }());
  return gen;
}

std::shared_ptr<const vocabulary::Vocabulary> vocab() {
  static auto voc = yolo_slam::test_support::shippedVocabulary();
  return voc;
}

using ::test_support::readBytes;
using ::test_support::writeBytes;

void feed(slam::System& sys, size_t first, size_t last) {
  for (size_t i = first; i <= last; ++i) {
    const sim::SynthFrame f = generator().frame(i);
    sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {});
  }
}

void expectSameSnapshot(const slam::MapSnapshot& a, const slam::MapSnapshot& b) {
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t i = 0; i < a.points.size(); ++i) EXPECT_EQ(a.points[i], b.points[i]) << "point " << i;
  ASSERT_EQ(a.keyframes.size(), b.keyframes.size());
  for (size_t i = 0; i < a.keyframes.size(); ++i) {
    EXPECT_EQ(a.keyframes[i].stamp, b.keyframes[i].stamp);
    EXPECT_TRUE(a.keyframes[i].T_wc.matrix() == b.keyframes[i].T_wc.matrix()) << "keyframe " << i;
  }
  EXPECT_EQ(a.covisibility_edges, b.covisibility_edges);
}

// The map of frames 0..kMappedFrames-1, saved once for all tests.
class SlamMapFile : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    builder_ = new slam::System(generator().camera(), testOptions(), vocab());
    feed(*builder_, 0, kMappedFrames - 1);
    info_ = builder_->saveMap(file());
  }
  static void TearDownTestSuite() {
    delete builder_;
    delete dir_;
  }
  static std::string file() { return dir_->path() + "/map.ysmap"; }
  static std::string path(const std::string& name) { return dir_->path() + "/" + name; }

  static test::TempDir* dir_;
  static slam::System* builder_;
  static slam::MapFileInfo info_;
};
test::TempDir* SlamMapFile::dir_ = nullptr;
slam::System* SlamMapFile::builder_ = nullptr;
slam::MapFileInfo SlamMapFile::info_;

TEST_F(SlamMapFile, RoundTripGivesIdenticalBytesAndMap) {
  ASSERT_GT(info_.keyframes, 2u);
  ASSERT_GT(info_.map_points, 100u);
  slam::System loaded(generator().camera(), testOptions(), vocab());
  const slam::MapFileInfo in = loaded.loadMap(file());
  EXPECT_EQ(in.keyframes, info_.keyframes);
  EXPECT_EQ(in.map_points, info_.map_points);
  EXPECT_EQ(in.bytes, info_.bytes);
  EXPECT_EQ(loaded.state(), slam::TrackingState::Lost);
  expectSameSnapshot(builder_->mapSnapshot(), loaded.mapSnapshot());
  loaded.saveMap(path("again.ysmap"));
  EXPECT_TRUE(readBytes(file()) == readBytes(path("again.ysmap"))) << "second save differs";
  std::printf("map of %zu keyframes, %zu points: %zu bytes, saved in %.1f ms, loaded in %.1f ms\n",
              info_.keyframes, info_.map_points, info_.bytes, info_.ms, in.ms);
}

TEST_F(SlamMapFile, LoadRebuildsTheIndexes) {
  vocabulary::KeyFrameDatabase db;
  slam::Map map;
  map.setKeyFrameDatabase(&db);
  slam::MapFileContext ctx;
  ctx.camera = generator().camera();
  ctx.vocabulary = vocab().get();
  slam::loadMapFile(file(), ctx, map);
  std::lock_guard<std::mutex> lk(map.update_mutex);
  EXPECT_EQ(db.size(), map.numKeyFrames());
  ASSERT_TRUE(map.origin());
  EXPECT_TRUE(map.origin()->is_origin);
  for (const auto& kf : map.keyframes()) {
    EXPECT_FALSE(kf->f.bow.empty()) << "keyframe " << kf->id;
    EXPECT_EQ(kf->ordered_connections.size(), kf->connections.size());
    if (kf->parent) {
      EXPECT_EQ(kf->parent->children.count(kf.get()), 1u);
    }
    EXPECT_TRUE(kf == map.origin() || kf->parent) << "keyframe " << kf->id << " outside the spanning tree";
    for (int i = 0; i < kf->f.N; ++i) {
      const slam::MapPointPtr& mp = kf->f.points[i];
      if (mp) {
        EXPECT_EQ(mp->observations.at(kf), static_cast<size_t>(i));
      }
    }
  }
  for (const auto& mp : map.mapPoints()) {
    EXPECT_EQ(mp->descriptor.cols, 32);
    EXPECT_GT(mp->max_dist, mp->min_dist);
    EXPECT_TRUE(mp->ref_kf && mp->inKeyFrame(mp->ref_kf));
  }
  EXPECT_GE(map.nextKeyFrameId(), static_cast<long>(map.keyframes().back()->id + 1));
}

// Loading `bad` into `sys` fails with an Error naming the file and containing `expected`, and
// leaves sys's map and tracking state as they were.
void expectRefused(slam::System& sys, const std::string& bad, const std::string& expected) {
  const slam::MapSnapshot before = sys.mapSnapshot();
  const slam::TrackingState state = sys.state();
  try {
    sys.loadMap(bad);
    ADD_FAILURE() << bad << " was loaded";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(bad), std::string::npos) << msg;
    EXPECT_NE(msg.find(expected), std::string::npos) << msg;
    std::printf("%s\n", msg.c_str());
  }
  expectSameSnapshot(before, sys.mapSnapshot());
  EXPECT_EQ(sys.state(), state);
}

TEST_F(SlamMapFile, DamagedFilesAreRefusedAndTheMapStays) {
  slam::System sys(generator().camera(), testOptions(), vocab());
  sys.loadMap(file());
  const std::string good = readBytes(file());
  expectRefused(sys, path("missing.ysmap"), "not found");
  writeBytes(path("truncated.ysmap"), good.substr(0, good.size() / 2));
  expectRefused(sys, path("truncated.ysmap"), "truncated");
  writeBytes(path("short.ysmap"), good.substr(0, kVersionOffset));
  expectRefused(sys, path("short.ysmap"), "truncated");
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x01;
  writeBytes(path("flipped.ysmap"), flipped);
  expectRefused(sys, path("flipped.ysmap"), "checksum");
  std::string version = good;
  version[kVersionOffset] ^= 0x40;
  writeBytes(path("version.ysmap"), version);
  expectRefused(sys, path("version.ysmap"), "format version");
  writeBytes(path("trailing.ysmap"), good + "x");
  expectRefused(sys, path("trailing.ysmap"), "corrupted");
  writeBytes(path("other.ysmap"), std::string(good.size(), 'x'));
  expectRefused(sys, path("other.ysmap"), "not a yolo_slam map file");
}

TEST_F(SlamMapFile, AnotherVocabularyCameraOrPyramidIsRefused) {
  // A two-word vocabulary: a root and two leaves.
  auto other_voc = vocabulary::Vocabulary::fromNodes(2, 1, vocabulary::Weighting::TfIdf, vocabulary::Scoring::L1,
                                                     {0, 0, 0}, std::vector<uint8_t>(3 * 32, 0x0f), {0, 1, 1}, {});
  slam::System voc_sys(generator().camera(), testOptions(), other_voc);
  feed(voc_sys, 0, kFramesBeforeBadLoad - 1);
  expectRefused(voc_sys, file(), "another vocabulary");
  slam::System no_voc(generator().camera(), testOptions(), nullptr);
  feed(no_voc, 0, kFramesBeforeBadLoad - 1);
  expectRefused(no_voc, file(), "another vocabulary");

  CameraModel cam = generator().camera();
  cam.fx *= 1.01;
  slam::System cam_sys(cam, testOptions(), vocab());
  feed(cam_sys, 0, kFramesBeforeBadLoad - 1);
  expectRefused(cam_sys, file(), "another camera");

  slam::SystemOptions pyramid = testOptions();
  pyramid.orb.n_levels = kOtherPyramidLevels;
  slam::System orb_sys(generator().camera(), pyramid, vocab());
  expectRefused(orb_sys, file(), "ORBextractor.nLevels");
}

TEST_F(SlamMapFile, LocalizationRelocalisesInALoadedMap) {
  slam::System sys(generator().camera(), testOptions(), vocab());
  sys.setLocalizationOnly(true);  // before the first frame and before the load
  const size_t corrections_before = sys.mapCorrections();
  sys.loadMap(file());
  EXPECT_GT(sys.mapCorrections(), corrections_before) << "a loaded map must count as a map correction (odom)";
  const Pose T_w0 = generator().frame(0).T_wc;  // the map's world frame is its first camera
  int tracked = 0;
  for (size_t i = kLaterFirst; i <= kLaterLast; ++i) {
    const sim::SynthFrame f = generator().frame(i);
    const slam::TrackResult r = sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {});
    if (r.state != slam::TrackingState::Ok) continue;
    ++tracked;
    const Pose gt = T_w0.inverse() * f.T_wc;
    EXPECT_LT((gt.translation() - r.T_wc.translation()).norm(), kMaxPoseError) << "frame " << i;
  }
  const slam::SystemStats s = sys.stats();
  std::printf("localization in the loaded map: %d of %zu frames tracked, %zu relocalisations\n", tracked,
              kLaterLast - kLaterFirst + 1, s.relocalizations);
  EXPECT_GE(s.relocalizations, 1u);
  EXPECT_GE(sys.mapCorrections(), 1 + s.relocalizations);
  sys.reset();
  EXPECT_GE(sys.mapCorrections(), 2 + s.relocalizations);
  EXPECT_GE(tracked, static_cast<int>(kLaterLast - kLaterFirst) - 2);
  EXPECT_EQ(s.keyframes, info_.keyframes) << "localization mode added keyframes";
  EXPECT_EQ(s.map_points, info_.map_points) << "localization mode changed the map";
}

}  // namespace

// Threaded back end with loop closing, mapping on: the loaded map is extended, and the extended
// map saves and loads again.
TEST(SlamMapFileThreaded, MappingContinuesInALoadedMap) {
  test::TempDir dir;
  const std::string first = dir.path() + "/first.ysmap", second = dir.path() + "/second.ysmap";
  slam::SystemOptions opt = testOptions();
  opt.sequential = false;
  opt.slam.loop.enabled = true;
  slam::MapFileInfo built;
  {
    slam::System builder(generator().camera(), opt, vocab());
    feed(builder, 0, kMappedFrames - 1);
    builder.waitForLoopClosing();
    built = builder.saveMap(first);
  }
  slam::System sys(generator().camera(), opt, vocab());
  sys.loadMap(first);
  int tracked = 0;
  for (size_t i = kLaterFirst; i <= kLaterLast; ++i) {
    const sim::SynthFrame f = generator().frame(i);
    tracked += sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {}).state == slam::TrackingState::Ok ? 1 : 0;
  }
  sys.waitForLoopClosing();
  EXPECT_GE(sys.stats().relocalizations, 1u);
  EXPECT_GE(tracked, static_cast<int>(kLaterLast - kLaterFirst) - 2);
  const slam::MapFileInfo extended = sys.saveMap(second);
  EXPECT_GE(extended.keyframes, built.keyframes);
  slam::System again(generator().camera(), opt, vocab());
  EXPECT_EQ(again.loadMap(second).keyframes, extended.keyframes);
  std::printf("loaded map of %zu keyframes extended to %zu while tracking %d frames\n", built.keyframes,
              extended.keyframes, tracked);
}
