// Bounded random-mutation fuzzing of the readers of user files: the TUM lists (rgb.txt,
// depth.txt, associations.txt, groundtruth.txt), the YAML settings loader with the camera, and the
// depth decoder (PNG bytes). Valid inputs are mutated (test_support::Mutator, seeded); each
// mutant must be read or refused with yolo_slam::Error, never crash or throw anything else.
// YS_FUZZ_ITERATIONS mutants per target (default a few seconds' worth; scripts/sanitize.sh runs
// more under ASan/UBSan). The vocabulary and map-file readers have the same test beside their
// modules (test/vocabulary, test/slam).
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/io/depth.h"
#include "yolo_slam/io/trajectory.h"
#include "yolo_slam/io/tum_sequence.h"

#include "support/mutate.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

using namespace yolo_slam;

namespace {

constexpr int kDefaultIterations = 400;
constexpr int kFrames = 20;

std::string readAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void writeAll(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

class FuzzReaders : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/ys_fuzz_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

  // Feeds `iterations` mutants of `valid` to `read`; a non-Error exception fails the test and
  // leaves the mutant in /tmp for a rerun. (A crash ends the test binary: the seed and the
  // iteration printed before each mutant when YS_FUZZ_VERBOSE is set find it.)
  // `checksummed`: a format whose checksums refuse nearly every mutant (PNG).
  void fuzz(const std::string& target, const std::string& valid, unsigned seed,
            const std::function<void(const std::string&)>& read, bool checksummed = false) {
    test_support::Mutator m(seed);
    const int n = test_support::fuzzIterations(kDefaultIterations);
    int refused = 0;
    for (int i = 0; i < n; ++i) {
      const std::string mutant = m.mutate(valid);
      if (std::getenv("YS_FUZZ_VERBOSE")) std::fprintf(stderr, "%s %d\n", target.c_str(), i);
      try {
        read(mutant);
      } catch (const Error&) {
        ++refused;
      } catch (const std::exception& e) {
        const std::string keep = "/tmp/ys_fuzz_" + target + "_" + std::to_string(i);
        writeAll(keep, mutant);
        ADD_FAILURE() << target << " mutant " << i << " (kept in " << keep << ") threw a non-Error: " << e.what();
        return;
      }
    }
    // The mutations must reach the checks: some mutants are refused, and (but for a checksummed
    // format) not all, so that the parser behind the first checks is reached too.
    EXPECT_GT(refused, 0) << target;
    if (!checksummed) {
      EXPECT_LT(refused, n) << target;
    }
  }

  std::string path(const std::string& name) const { return joinPath(dir_, name); }
  std::string dir_;
};

// "stamp file" lines of a list, stamps 1/30 s apart.
std::string fileList(const char* folder, double offset) {
  std::string s = "# timestamp filename\n";
  for (int i = 0; i < kFrames; ++i) {
    char line[96];
    std::snprintf(line, sizeof line, "%.6f %s/%06d.png\n", 1305031102.0 + offset + i / 30.0, folder, i);
    s += line;
  }
  return s;
}

std::string groundTruth() {
  std::string s = "# timestamp tx ty tz qx qy qz qw\n";
  for (int i = 0; i < kFrames; ++i) {
    char line[160];
    std::snprintf(line, sizeof line, "%.4f %.4f %.4f %.4f 0.0 0.0 0.38 0.92\n", 1305031102.0 + i / 100.0, 0.01 * i,
                  -0.5, 1.4 + 0.002 * i);
    s += line;
  }
  return s;
}

}  // namespace

TEST_F(FuzzReaders, TumLists) {
  const std::string rgb = fileList("rgb", 0), depth = fileList("depth", 0.004), gt = groundTruth();
  auto open = [&](const std::string& rgb_txt, const std::string& depth_txt, const std::string& gt_txt) {
    writeAll(path("rgb.txt"), rgb_txt);
    writeAll(path("depth.txt"), depth_txt);
    writeAll(path("groundtruth.txt"), gt_txt);
    const io::TumSequence seq = io::TumSequence::open(dir_);
    ASSERT_GT(seq.size(), 0u);
  };
  fuzz("rgb_txt", rgb, 1, [&](const std::string& m) { open(m, depth, gt); });
  fuzz("depth_txt", depth, 2, [&](const std::string& m) { open(rgb, m, gt); });
  // A bad groundtruth.txt is a warning: the sequence opens (without ground truth).
  fuzz("trajectory", gt, 3, [&](const std::string& m) {
    writeAll(path("traj.txt"), m);
    io::readTrajectory(path("traj.txt"));
  });
}

TEST_F(FuzzReaders, AssociationsFile) {
  std::string assoc;
  for (int i = 0; i < kFrames; ++i) {
    char line[160];
    std::snprintf(line, sizeof line, "%.6f rgb/%06d.png %.6f depth/%06d.png\n", 1305031102.0 + i / 30.0, i,
                  1305031102.004 + i / 30.0, i);
    assoc += line;
  }
  fuzz("associations", assoc, 4, [&](const std::string& m) {
    writeAll(path("associations.txt"), m);
    io::TumSequence::open(dir_);
  });
}

TEST_F(FuzzReaders, YamlSettingsAndCamera) {
  const std::string valid = readAll(joinPath(YOLO_SLAM_SOURCE_DIR, "config/TUM3.yaml"));
  ASSERT_FALSE(valid.empty());
  ::testing::internal::CaptureStderr();  // unknown-key warnings of the mutants
  fuzz("yaml", valid, 5, [&](const std::string& m) {
    writeAll(path("settings.yaml"), m);
    const Config cfg = Config::fromFile(path("settings.yaml"));
    const CameraModel cam = CameraModel::load(cfg);
    EXPECT_TRUE(std::isfinite(cam.fx) && std::isfinite(cam.cx) && std::isfinite(cam.max_depth));
    cfg.getStringList("Detector.dynamicClasses", {});
    cfg.getString("Screening.mode", "");
    cfg.getBool("LoopClosing.enabled", true);
    cfg.getInt("ORBextractor.nFeatures", 0);
  });
  ::testing::internal::GetCapturedStderr();
}

// The decoded depth of a mutant is CV_32F metres, finite and >= 0, or the mutant was refused.
void expectCleanDepth(const cv::Mat& d) {
  ASSERT_EQ(d.type(), CV_32FC1);
  for (int r = 0; r < d.rows; ++r)
    for (int c = 0; c < d.cols; ++c) ASSERT_TRUE(std::isfinite(d.at<float>(r, c)) && d.at<float>(r, c) >= 0);
}

TEST_F(FuzzReaders, DepthImages) {
  cv::Mat depth(48, 64, CV_16UC1);
  cv::randu(depth, 0, 40000);
  ::testing::internal::CaptureStderr();  // libpng's own messages about the mutants
  // PNG (TUM depth): its CRCs refuse nearly every mutant; 16-bit PGM has none, so mutants reach
  // the decoder.
  for (const char* ext : {".png", ".pgm"}) {
    std::vector<uchar> bytes;
    ASSERT_TRUE(cv::imencode(ext, depth, bytes));
    const std::string file = path(std::string("d") + ext);
    fuzz(std::string("depth") + (ext + 1), std::string(bytes.begin(), bytes.end()), 6, [&](const std::string& m) {
      writeAll(file, m);
      expectCleanDepth(io::loadDepth(file, 5000.0));
    }, std::string(ext) == ".png");
  }
  ::testing::internal::GetCapturedStderr();
}
