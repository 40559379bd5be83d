// Bounded random-mutation fuzzing of the vocabulary readers (text ORBvoc format and the binary
// format, through Vocabulary::load, which picks by the magic): a small trained vocabulary is
// saved in both formats and mutated (test_support::Mutator, seeded). Each mutant must load or be
// refused with yolo_slam::Error whose message has no raw binary bytes. YS_FUZZ_ITERATIONS
// mutants per format.
#include "yolo_slam/common/error.h"
#include "yolo_slam/vocabulary/trainer.h"
#include "yolo_slam/vocabulary/vocabulary.h"
#include "support/temp_dir.h"

#include "support/mutate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <random>

using namespace yolo_slam;
using namespace yolo_slam::vocabulary;

namespace {

constexpr int kDefaultIterations = 300;

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// A k=3, L=2 vocabulary of random descriptors: small enough to mutate quickly.
std::shared_ptr<Vocabulary> tinyVocabulary() {
  std::mt19937 rng(3);
  std::vector<cv::Mat> images;
  for (int i = 0; i < 6; ++i) {
    cv::Mat d(40, 32, CV_8U);
    for (int r = 0; r < d.rows; ++r)
      for (int c = 0; c < 32; ++c) d.at<uint8_t>(r, c) = static_cast<uint8_t>(rng());
    images.push_back(d);
  }
  TrainerOptions opt;
  opt.k = 3;
  opt.levels = 2;
  opt.seed = 1;
  return trainVocabulary(images, opt);
}

bool printable(const std::string& s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isprint(static_cast<unsigned char>(c)) != 0; });
}

// Mutants of `valid` loaded from `file`; returns how many were refused.
int fuzz(const std::string& valid, const std::string& file, unsigned seed) {
  test_support::Mutator m(seed);
  const int n = test_support::fuzzIterations(kDefaultIterations);
  int refused = 0;
  for (int i = 0; i < n; ++i) {
    const std::string mutant = m.mutate(valid);
    writeBytes(file, mutant);
    try {
      Vocabulary::load(file);
    } catch (const Error& e) {
      ++refused;
      EXPECT_TRUE(printable(e.what())) << "mutant " << i << ": " << e.what();
    } catch (const std::exception& e) {
      const std::string keep = file + ".failed_" + std::to_string(i);
      writeBytes(keep, mutant);
      ADD_FAILURE() << "mutant " << i << " (kept in " << keep << ") threw a non-Error: " << e.what();
      break;
    }
  }
  return refused;
}

}  // namespace

TEST(FuzzVocabulary, TextAndBinaryMutantsLoadOrAreRefusedCleanly) {
  test::TempDir dir;
  const auto voc = tinyVocabulary();
  const std::string text = dir.path() + "/v.txt", binary = dir.path() + "/v.vocab";
  voc->saveText(text);
  voc->save(binary);
  const int n = test_support::fuzzIterations(kDefaultIterations);
  const int text_refused = fuzz(readBytes(text), dir.path() + "/m.txt", 21);
  EXPECT_GT(text_refused, 0);
  EXPECT_LT(text_refused, n) << "some text mutants (a changed weight, a trailing line) still load";
  EXPECT_GT(fuzz(readBytes(binary), dir.path() + "/m.vocab", 22), 0);
}
