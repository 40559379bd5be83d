#include "yolo_slam/common/error.h"
#include "yolo_slam/vocabulary/trainer.h"
#include "yolo_slam/vocabulary/vocabulary.h"
#include "support/temp_dir.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>

using namespace yolo_slam;
using namespace yolo_slam::vocabulary;
using yolo_slam::test::TempDir;

namespace {

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

// Random descriptors grouped around a few prototypes so the tree has structure.
std::vector<cv::Mat> randomImages(int n_images, int per_image, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<cv::Mat> protos;
  for (int p = 0; p < 40; ++p) {
    cv::Mat d(1, 32, CV_8U);
    for (int b = 0; b < 32; ++b) d.at<uint8_t>(b) = static_cast<uint8_t>(rng());
    protos.push_back(d);
  }
  std::vector<cv::Mat> images;
  for (int i = 0; i < n_images; ++i) {
    cv::Mat m(per_image, 32, CV_8U);
    for (int r = 0; r < per_image; ++r) {
      protos[rng() % protos.size()].copyTo(m.row(r));
      for (int flip = 0; flip < 12; ++flip) {  // ~12 random bit flips off the prototype
        const int bit = static_cast<int>(rng() % 256);
        m.at<uint8_t>(r, bit / 8) ^= static_cast<uint8_t>(1u << (bit % 8));
      }
    }
    images.push_back(m);
  }
  return images;
}

std::shared_ptr<Vocabulary> smallVocab(uint64_t seed = 1) {
  TrainerOptions opt;
  opt.k = 4;
  opt.levels = 3;
  opt.seed = seed;
  return trainVocabulary(randomImages(30, 60, 7), opt);
}

std::string descLine(int parent, int leaf, int byte, double weight) {
  std::ostringstream os;
  os << parent << ' ' << leaf;
  for (int b = 0; b < 32; ++b) os << ' ' << byte;
  os << ' ' << weight << '\n';
  return os.str();
}

cv::Mat constDesc(int byte) { return cv::Mat(1, 32, CV_8U, cv::Scalar(byte)); }

// k=2, L=2: root -> {A (zeros), B (ones)}; A -> {0x00, 0x0F}, B -> {0xFF, 0xF0}.
std::string handWrittenOrbVoc() {
  return "2 2 0 0\n" + descLine(0, 0, 0x00, 0) + descLine(0, 0, 0xFF, 0) + descLine(1, 1, 0x00, 0.5) +
         descLine(1, 1, 0x0F, 0.25) + descLine(2, 1, 0xFF, 1.0) + descLine(2, 1, 0xF0, 2.0);
}

}  // namespace

TEST(Vocabulary, SaveLoadRoundTripIsBitIdentical) {
  TempDir tmp;
  ASSERT_TRUE(tmp.ok());
  auto v = smallVocab();
  ASSERT_GT(v->size(), 16u);
  const std::string a = tmp.file("a.vocab"), b = tmp.file("b.vocab");
  v->save(a);
  auto w = Vocabulary::load(a);
  EXPECT_TRUE(v->identical(*w));
  EXPECT_EQ(w->size(), v->size());
  EXPECT_EQ(w->branching(), 4);
  EXPECT_EQ(w->levels(), 3);
  w->save(b);
  EXPECT_EQ(readBytes(a), readBytes(b));
  // Same words for the same descriptors.
  auto imgs = randomImages(2, 50, 99);
  BowVector bv, bw;
  FeatureVector fv, fw;
  v->transform(imgs[0], bv, fv, 1);
  w->transform(imgs[0], bw, fw, 1);
  EXPECT_EQ(bv, bw);
  EXPECT_EQ(fv, fw);
}

TEST(Vocabulary, CorruptOrMissingFilesAreErrorsNamingTheFile) {
  TempDir tmp;
  ASSERT_TRUE(tmp.ok());
  auto v = smallVocab();
  const std::string p = tmp.file("c.vocab");
  v->save(p);
  const std::string good = readBytes(p);

  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  writeBytes(p, flipped);
  try {
    Vocabulary::load(p);
    FAIL() << "corrupt payload loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("checksum"), std::string::npos) << e.what();
  }
  writeBytes(p, good.substr(0, good.size() - 7));
  try {
    Vocabulary::load(p);
    FAIL() << "truncated file loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  writeBytes(p, good.substr(0, 30));
  EXPECT_THROW(Vocabulary::load(p), Error);
  std::string badversion = good;
  badversion[8] = 9;
  writeBytes(p, badversion);
  try {
    Vocabulary::load(p);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("version"), std::string::npos) << e.what();
  }
  std::remove(p.c_str());
  try {
    Vocabulary::load(p);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(p), std::string::npos);
  }
}

TEST(Vocabulary, ReadsHandWrittenOrbVocText) {
  TempDir tmp;
  ASSERT_TRUE(tmp.ok());
  const std::string p = tmp.file("orbvoc.txt");
  writeBytes(p, handWrittenOrbVoc());
  auto v = Vocabulary::load(p);
  EXPECT_EQ(v->branching(), 2);
  EXPECT_EQ(v->levels(), 2);
  EXPECT_EQ(v->weighting(), Weighting::TfIdf);
  ASSERT_EQ(v->size(), 4u);
  ASSERT_EQ(v->nodeCount(), 7u);
  // Words numbered in file order, weights as written.
  EXPECT_DOUBLE_EQ(v->wordWeight(0), 0.5);
  EXPECT_DOUBLE_EQ(v->wordWeight(1), 0.25);
  EXPECT_DOUBLE_EQ(v->wordWeight(2), 1.0);
  EXPECT_DOUBLE_EQ(v->wordWeight(3), 2.0);
  EXPECT_EQ(v->transform(constDesc(0x00).ptr<uint8_t>()), 0u);
  EXPECT_EQ(v->transform(constDesc(0x07).ptr<uint8_t>()), 1u);  // 0x07: 1 bit from 0x0F per byte
  EXPECT_EQ(v->transform(constDesc(0xFE).ptr<uint8_t>()), 2u);
  EXPECT_EQ(v->transform(constDesc(0xF8).ptr<uint8_t>()), 3u);  // closer to B, then to 0xF0
  NodeId n = 0;
  v->transform(constDesc(0x0F).ptr<uint8_t>(), 1, &n);
  EXPECT_EQ(n, 1u);  // level-1 node "A"
  EXPECT_EQ(v->nodeLevel(n), 1);
  v->transform(constDesc(0xF8).ptr<uint8_t>(), 1, &n);
  EXPECT_EQ(n, 2u);

  // tf-idf bag of words: two descriptors of word 0 (w 0.5) and one of word 3 (w 2.0).
  cv::Mat d;
  cv::vconcat(std::vector<cv::Mat>{constDesc(0), constDesc(0), constDesc(0xF8)}, d);
  BowVector bow;
  FeatureVector fv;
  v->transform(d, bow, fv, 1);
  ASSERT_EQ(bow.size(), 2u);
  EXPECT_NEAR(bow[0], 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(bow[3], 2.0 / 3.0, 1e-12);
  ASSERT_EQ(fv.size(), 2u);
  EXPECT_EQ(fv[1], (std::vector<unsigned>{0, 1}));
  EXPECT_EQ(fv[2], (std::vector<unsigned>{2}));

  // Text writer and binary round trip keep the same vocabulary.
  const std::string t2 = tmp.file("orbvoc2.txt"), b = tmp.file("orbvoc.vocab");
  v->saveText(t2);
  EXPECT_TRUE(Vocabulary::loadText(t2)->identical(*v));
  v->save(b);
  EXPECT_TRUE(Vocabulary::load(b)->identical(*v));
}

TEST(Vocabulary, TextReaderErrorsNameFileAndLine) {
  TempDir tmp;
  ASSERT_TRUE(tmp.ok());
  const std::string p = tmp.file("bad.txt");
  auto expectError = [&](const std::string& text, const std::string& needle) {
    writeBytes(p, text);
    try {
      Vocabulary::load(p);
      ADD_FAILURE() << "loaded: " << needle;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  std::string t = handWrittenOrbVoc();
  expectError("2 2 0 0\n" + descLine(0, 0, 0, 0) + descLine(0, 0, 300, 0), p + ":3");  // byte > 255
  expectError("2 2 0 0\n" + descLine(0, 0, 0, 0) + "0 1 1 2 3\n", p + ":3");            // short line
  expectError("2 2 0 0\n" + descLine(5, 1, 0, 0), p + ":2");                             // forward parent
  expectError("2 2 3 0\n" + descLine(0, 1, 0, 0), "scoring");                            // unsupported
  expectError("2 2 0 0\n" + descLine(0, 0, 0, 0), "no children");                        // inner w/o kids
  expectError("", "empty");
}

TEST(Vocabulary, ScoreProperties) {
  auto v = smallVocab();
  auto imgs = randomImages(3, 80, 123);
  BowVector a, b;
  v->transform(imgs[0], a);
  v->transform(imgs[1], b);
  ASSERT_FALSE(a.empty());
  double sum = 0;
  for (const auto& kv : a) sum += kv.second;
  EXPECT_NEAR(sum, 1.0, 1e-9);  // L1-normalised
  EXPECT_NEAR(Vocabulary::score(a, a), 1.0, 1e-12);
  EXPECT_NEAR(Vocabulary::score(a, b), Vocabulary::score(b, a), 1e-12);
  EXPECT_GT(Vocabulary::score(a, b), 0.0);
  EXPECT_LT(Vocabulary::score(a, b), 1.0);
  EXPECT_DOUBLE_EQ(Vocabulary::score(BowVector{{1, 1.0}}, BowVector{{2, 1.0}}), 0.0);
  EXPECT_DOUBLE_EQ(Vocabulary::score(BowVector{{1, 0.5}, {2, 0.5}}, BowVector{{2, 0.5}, {3, 0.5}}), 0.5);
  EXPECT_DOUBLE_EQ(Vocabulary::score(BowVector{}, a), 0.0);
}

TEST(Vocabulary, TransformInputChecksAndDirectIndex) {
  auto v = smallVocab();
  BowVector bow{{1, 1.0}};
  FeatureVector fv{{1, {0}}};
  v->transform(cv::Mat(), bow, fv, 1);
  EXPECT_TRUE(bow.empty());
  EXPECT_TRUE(fv.empty());
  EXPECT_THROW(v->transform(cv::Mat(3, 16, CV_8U), bow, fv, 1), Error);
  EXPECT_THROW(v->transform(cv::Mat(3, 32, CV_32F), bow, fv, 1), Error);

  auto imgs = randomImages(1, 200, 5);
  v->transform(imgs[0], bow, fv, 1);
  // Every feature whose word has weight > 0 appears once, under a node at level L-1 that is an
  // ancestor of its word's leaf (or the leaf itself where the branch ends higher).
  size_t listed = 0;
  for (const auto& node : fv) {
    for (unsigned i : node.second) {
      ++listed;
      NodeId at = 0;
      const WordId w = v->transform(imgs[0].ptr<uint8_t>(static_cast<int>(i)), 1, &at);
      EXPECT_EQ(at, node.first);
      NodeId x = v->wordNode(w);
      while (x != 0 && x != node.first) x = v->parent(x);
      EXPECT_EQ(x, node.first);
    }
  }
  size_t weighted = 0;
  for (int r = 0; r < imgs[0].rows; ++r)
    weighted += v->wordWeight(v->transform(imgs[0].ptr<uint8_t>(r))) > 0 ? 1 : 0;
  EXPECT_EQ(listed, weighted);
  EXPECT_GT(listed, 100u);
}

TEST(Vocabulary, FromNodesRejectsBadTrees) {
  std::vector<uint8_t> d(3 * 32, 0);
  std::vector<double> w(3, 1.0);
  EXPECT_THROW(Vocabulary::fromNodes(2, 1, Weighting::TfIdf, Scoring::L1, {0, 0, 7}, d, w, {}), Error);
  EXPECT_THROW(Vocabulary::fromNodes(2, 1, Weighting::TfIdf, Scoring::L1, {0, 0, 1}, d, w, {}), Error);  // depth 2 > L
  EXPECT_THROW(Vocabulary::fromNodes(2, 1, Weighting::TfIdf, Scoring::L1, {0, 2, 1}, d, w, {}), Error);  // cycle
  auto ok = Vocabulary::fromNodes(2, 1, Weighting::TfIdf, Scoring::L1, {0, 0, 0}, d, w, {});
  EXPECT_EQ(ok->size(), 2u);
}
