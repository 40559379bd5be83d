// Bounded random-mutation fuzzing of the map-file reader (slam/map_file.h): a small map of a
// synthetic static_xyz run is saved, then mutated (test_support::Mutator, seeded). Plain mutants
// exercise the header, size and checksum checks; "re-sealed" mutants get a header that matches
// their payload (size and FNV-1a checksum recomputed), so that the payload parser and the map
// rebuild see the corruption. Each must load or be refused with yolo_slam::Error, never crash,
// throw anything else or allocate beyond the file. YS_FUZZ_ITERATIONS mutants per mode.
#include "support/bytes.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_file.h"
#include "yolo_slam/slam/system.h"

#include "support/temp_dir.h"
#include "support/mutate.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <sstream>

using namespace yolo_slam;

namespace {

constexpr int kDefaultIterations = 300;
constexpr size_t kFrames = 12;
// Portable binary header: endianness flag (1), magic (8), version (4), payload size (8),
// payload checksum (8); little-endian.
constexpr size_t kSizeOffset = 13, kChecksumOffset = 21, kHeaderBytes = 29;
constexpr uint64_t kFnvBasis = 1469598103934665603ull, kFnvPrime = 1099511628211ull;

using ::test_support::readBytes;
using ::test_support::writeBytes;

// `header` (the original's) with the size and checksum of `payload`.
std::string resealed(const std::string& header, const std::string& payload) {
  uint64_t sum = kFnvBasis;
  for (unsigned char c : payload) sum = (sum ^ c) * kFnvPrime;
  const uint64_t size = payload.size();
  std::string h = header;
  std::memcpy(&h[kSizeOffset], &size, 8);
  std::memcpy(&h[kChecksumOffset], &sum, 8);
  return h + payload;
}

class FuzzMapFile : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sim::SynthOptions so;
    so.preset = "static_xyz";
    so.frames = static_cast<int>(kFrames);
    so.seed = 4;
    sim::SequenceGenerator gen(so);
    camera_ = gen.camera();
    slam::SystemOptions o = slam::SystemOptions::load(Config());
    o.screening.mode = screening::DynamicMode::Off;
    o.slam.loop.enabled = false;
    o.sequential = true;
    slam::System sys(camera_, o, nullptr);
    for (size_t i = 0; i < kFrames; ++i) {
      const sim::SynthFrame f = gen.frame(i);
      sys.trackRgbd(f.bgr, f.depth, f.rgb_stamp, {});
    }
    dir_ = new test::TempDir;
    const std::string file = dir_->path() + "/valid.ysmap";
    sys.saveMap(file);
    valid_ = readBytes(file);
  }
  static void TearDownTestSuite() { delete dir_; }

  // Loads `bytes` as a map file into a new map; true if it loaded.
  static bool load(const std::string& bytes) {
    const std::string file = dir_->path() + "/mutant.ysmap";
    writeBytes(file, bytes);
    slam::Map map;
    slam::MapFileContext ctx;
    ctx.camera = camera_;
    slam::loadMapFile(file, ctx, map);
    return true;
  }

  // Feeds mutants made by `make` to the reader; counts the refused ones.
  template <class Make>
  int fuzz(unsigned seed, Make make) {
    test_support::Mutator m(seed);
    const int n = test_support::fuzzIterations(kDefaultIterations);
    int refused = 0;
    for (int i = 0; i < n; ++i) {
      const std::string mutant = make(m);
      try {
        load(mutant);
      } catch (const Error&) {
        ++refused;
      } catch (const std::exception& e) {
        const std::string keep = "/tmp/ys_fuzz_map_" + std::to_string(seed) + "_" + std::to_string(i) + ".ysmap";
        writeBytes(keep, mutant);
        ADD_FAILURE() << "mutant " << i << " (kept in " << keep << ") threw a non-Error: " << e.what();
        return refused;
      }
    }
    return refused;
  }

  static inline CameraModel camera_;
  static inline test::TempDir* dir_ = nullptr;
  static inline std::string valid_;
};

}  // namespace

TEST_F(FuzzMapFile, TheValidFileAndItsResealedCopyLoad) {
  ASSERT_GT(valid_.size(), kHeaderBytes);
  EXPECT_TRUE(load(valid_));
  const std::string header = valid_.substr(0, kHeaderBytes), payload = valid_.substr(kHeaderBytes);
  EXPECT_EQ(resealed(header, payload), valid_) << "the header layout this test assumes is wrong";
}

TEST_F(FuzzMapFile, PlainMutantsAreRefused) {
  const int n = test_support::fuzzIterations(kDefaultIterations);
  EXPECT_GT(fuzz(11, [](test_support::Mutator& m) { return m.mutate(valid_); }), n / 2);
}

TEST_F(FuzzMapFile, ResealedMutantsReachThePayloadChecks) {
  const std::string header = valid_.substr(0, kHeaderBytes), payload = valid_.substr(kHeaderBytes);
  const int refused = fuzz(12, [&](test_support::Mutator& m) { return resealed(header, m.mutate(payload)); });
  EXPECT_GT(refused, 0);
}
