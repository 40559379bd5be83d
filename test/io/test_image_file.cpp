#include "yolo_slam/common/paths.h"
#include "yolo_slam/io/image_file.h"

#include "support/mutate.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <unistd.h>
#include <vector>

#ifdef YOLO_SLAM_HAVE_LIBDEFLATE
#include <libdeflate.h>
#endif

using namespace yolo_slam;

namespace {

const char* kTum = "data/tum/rgbd_dataset_freiburg3_walking_xyz";

bool identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && (a.empty() || cv::norm(a, b, cv::NORM_INF) == 0);
}

std::string tempFile(const std::string& name, const std::vector<uint8_t>& bytes) {
  const std::string path = "/tmp/ys_image_file_" + std::to_string(::getpid()) + "_" + name;
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  return path;
}

std::vector<uint8_t> encode(const cv::Mat& m, std::vector<int> params = {}) {
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(".png", m, bytes, params));
  return bytes;
}

// readImage on `bytes` written to a file is exactly what cv::imread makes of that file.
void expectReadsAsImread(const std::vector<uint8_t>& bytes, const std::string& name, int flags) {
  const std::string path = tempFile(name, bytes);
  EXPECT_TRUE(identical(io::readImage(path, flags), cv::imread(path, flags))) << name << " flags " << flags;
  std::remove(path.c_str());
}

}  // namespace

TEST(ImageFile, RealTumFramesReadAsImreadReadsThem) {
  const std::string dir = joinPath(sharedDir(), kTum);
  for (const char* f : {"rgb/1341846313.592026.png", "rgb/1341846316.570121.png"}) {
    const std::string path = joinPath(dir, f);
    const cv::Mat fast = io::readImage(path, cv::IMREAD_COLOR);
    ASSERT_FALSE(fast.empty()) << path;
    EXPECT_EQ(fast.type(), CV_8UC3);
    EXPECT_TRUE(identical(fast, cv::imread(path, cv::IMREAD_COLOR))) << path;
  }
  for (const char* f : {"depth/1341846313.592088.png", "depth/1341846316.570146.png"}) {
    const std::string path = joinPath(dir, f);
    const cv::Mat fast = io::readImage(path, cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(fast.empty()) << path;
    EXPECT_EQ(fast.type(), CV_16UC1);
    EXPECT_TRUE(identical(fast, cv::imread(path, cv::IMREAD_UNCHANGED))) << path;
  }
}

TEST(ImageFile, MissingEmptyAndNonPngFilesReadAsImreadReadsThem) {
  EXPECT_TRUE(io::readImage("/nonexistent/ys_image.png", cv::IMREAD_COLOR).empty());
  expectReadsAsImread({}, "empty.png", cv::IMREAD_COLOR);
  expectReadsAsImread({'n', 'o', 't', ' ', 'a', 'n', ' ', 'i', 'm', 'a', 'g', 'e'}, "text.png", cv::IMREAD_COLOR);
  cv::Mat colour(37, 53, CV_8UC3);
  cv::randu(colour, 0, 255);
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", colour, jpeg));
  expectReadsAsImread(jpeg, "photo.jpg", cv::IMREAD_COLOR);
}

TEST(ImageFile, PngsOpenCvWritesReadAsImreadReadsThem) {
  cv::Mat colour(61, 83, CV_8UC3), grey(61, 83, CV_8UC1), depth(61, 83, CV_16UC1), rgba(61, 83, CV_8UC4);
  cv::randu(colour, 0, 255);
  cv::randu(grey, 0, 255);
  cv::randu(depth, 0, 65535);
  cv::randu(rgba, 0, 255);
  for (int level : {0, 1, 3, 9}) {
    const std::vector<int> p = {cv::IMWRITE_PNG_COMPRESSION, level};
    const std::string l = std::to_string(level);
    for (int flags : {cv::IMREAD_COLOR, cv::IMREAD_UNCHANGED}) {
      expectReadsAsImread(encode(colour, p), "colour" + l + ".png", flags);
      expectReadsAsImread(encode(grey, p), "grey" + l + ".png", flags);
      expectReadsAsImread(encode(depth, p), "depth" + l + ".png", flags);
      expectReadsAsImread(encode(rgba, p), "rgba" + l + ".png", flags);
      expectReadsAsImread(encode(grey, {cv::IMWRITE_PNG_BILEVEL, 1}), "bilevel.png", flags);
    }
  }
}

#ifdef YOLO_SLAM_HAVE_LIBDEFLATE

namespace {

void put32(std::vector<uint8_t>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(uint8_t(v >> s));
}

void putChunk(std::vector<uint8_t>& out, const std::string& type, const std::vector<uint8_t>& body) {
  put32(out, static_cast<uint32_t>(body.size()));
  std::vector<uint8_t> typed(type.begin(), type.end());
  typed.insert(typed.end(), body.begin(), body.end());
  out.insert(out.end(), typed.begin(), typed.end());
  put32(out, libdeflate_crc32(0, typed.data(), typed.size()));
}

uint8_t paethPredictor(int a, int b, int c) {
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  return uint8_t(pa <= pb && pa <= pc ? a : pb <= pc ? b : c);
}

// Row r of `rows` (big-endian samples, as PNG stores them) filtered with filters[r % size].
std::vector<uint8_t> filterRows(const std::vector<std::vector<uint8_t>>& rows, size_t bpp,
                                const std::vector<int>& filters) {
  std::vector<uint8_t> out;
  const std::vector<uint8_t> zeros(rows[0].size(), 0);
  for (size_t r = 0; r < rows.size(); ++r) {
    const int f = filters[r % filters.size()];
    const auto& cur = rows[r];
    const auto& up = r ? rows[r - 1] : zeros;
    out.push_back(uint8_t(f));
    for (size_t i = 0; i < cur.size(); ++i) {
      const int a = i >= bpp ? cur[i - bpp] : 0, b = up[i], c = i >= bpp ? up[i - bpp] : 0;
      const int pred = f == 1 ? a : f == 2 ? b : f == 3 ? (a + b) / 2 : f == 4 ? paethPredictor(a, b, c) : 0;
      out.push_back(uint8_t(cur[i] - pred));
    }
  }
  return out;
}

// A PNG built by hand: the rows filtered as asked, deflated, split over two IDAT chunks;
// `extra` chunks go between IHDR and IDAT.
std::vector<uint8_t> handPng(int w, const std::vector<std::vector<uint8_t>>& rows, uint8_t depth, uint8_t colour,
                             const std::vector<int>& filters,
                             const std::vector<std::pair<std::string, std::vector<uint8_t>>>& extra = {}) {
  const size_t bpp = (colour == 2 ? 3 : 1) * depth / 8;
  const std::vector<uint8_t> filtered = filterRows(rows, bpp, filters);
  libdeflate_compressor* c = libdeflate_alloc_compressor(6);
  std::vector<uint8_t> z(libdeflate_zlib_compress_bound(c, filtered.size()));
  z.resize(libdeflate_zlib_compress(c, filtered.data(), filtered.size(), z.data(), z.size()));
  libdeflate_free_compressor(c);
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'}, ihdr;
  put32(ihdr, uint32_t(w));
  put32(ihdr, uint32_t(rows.size()));
  ihdr.insert(ihdr.end(), {depth, colour, 0, 0, 0});
  putChunk(png, "IHDR", ihdr);
  for (const auto& e : extra) putChunk(png, e.first, e.second);
  const size_t half = z.size() / 2;
  putChunk(png, "IDAT", std::vector<uint8_t>(z.begin(), z.begin() + half));
  putChunk(png, "IDAT", std::vector<uint8_t>(z.begin() + half, z.end()));
  putChunk(png, "IEND", {});
  return png;
}

std::vector<std::vector<uint8_t>> randomRows(int w, int h, size_t bpp, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::vector<uint8_t>> rows(h, std::vector<uint8_t>(w * bpp));
  for (auto& r : rows)
    for (auto& v : r) v = uint8_t(rng() % 256);
  return rows;
}

struct Layout {
  const char* name;
  uint8_t depth, colour;
  size_t bpp;
  int flags;
};
const Layout kLayouts[] = {{"rgb8", 8, 2, 3, cv::IMREAD_COLOR},
                           {"rgb8", 8, 2, 3, cv::IMREAD_UNCHANGED},
                           {"grey8", 8, 0, 1, cv::IMREAD_COLOR},
                           {"grey8", 8, 0, 1, cv::IMREAD_UNCHANGED},
                           {"grey16", 16, 0, 2, cv::IMREAD_UNCHANGED}};

// The pixels the hand-built rows hold, as cv::imread would return them.
cv::Mat expectedPixels(const Layout& l, const std::vector<std::vector<uint8_t>>& rows, int w) {
  const int h = static_cast<int>(rows.size());
  cv::Mat m(h, w, l.depth == 16 ? CV_16UC1 : (l.colour == 2 || l.flags == cv::IMREAD_COLOR) ? CV_8UC3 : CV_8UC1);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const uint8_t* s = &rows[r][c * l.bpp];
      if (l.depth == 16)
        m.at<uint16_t>(r, c) = uint16_t((s[0] << 8) | s[1]);
      else if (m.channels() == 1)
        m.at<uint8_t>(r, c) = s[0];
      else if (l.colour == 2)
        m.at<cv::Vec3b>(r, c) = cv::Vec3b(s[2], s[1], s[0]);
      else
        m.at<cv::Vec3b>(r, c) = cv::Vec3b(s[0], s[0], s[0]);
    }
  return m;
}

}  // namespace

TEST(ImageFile, EveryRowFilterDecodesToThePixelsAndAsOpenCvDecodesIt) {
  const int w = 29, h = 23;
  const std::vector<std::vector<int>> filter_sets = {{0}, {1}, {2}, {3}, {4}, {0, 1, 2, 3, 4}, {4, 3, 2, 1, 0}};
  unsigned seed = 1;
  for (const auto& l : kLayouts)
    for (const auto& filters : filter_sets) {
      const auto rows = randomRows(w, h, l.bpp, seed++);
      const std::vector<uint8_t> png = handPng(w, rows, l.depth, l.colour, filters);
      const std::string what = std::string(l.name) + " flags " + std::to_string(l.flags) + " filter " +
                               std::to_string(filters[0]) + (filters.size() > 1 ? " mixed" : "");
      cv::Mat fast;
      ASSERT_TRUE(io::decodePlainPng(png.data(), png.size(), l.flags, &fast)) << what;
      EXPECT_TRUE(identical(fast, expectedPixels(l, rows, w))) << what;
      const cv::Mat viaOpenCv = cv::imdecode(png, l.flags);
      EXPECT_TRUE(identical(fast, viaOpenCv)) << what;
    }
}

TEST(ImageFile, TheFastPathTakesThePngsRgbdDatasetsWrite) {
  const std::string dir = joinPath(sharedDir(), kTum);
  for (const auto& f : {std::make_pair("rgb/1341846313.592026.png", cv::IMREAD_COLOR),
                        std::make_pair("depth/1341846313.592088.png", cv::IMREAD_UNCHANGED)}) {
    std::ifstream in(joinPath(dir, f.first), std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    cv::Mat out;
    EXPECT_TRUE(io::decodePlainPng(bytes.data(), bytes.size(), f.second, &out)) << f.first;
  }
  cv::Mat colour(40, 50, CV_8UC3), depth(40, 50, CV_16UC1);
  cv::randu(colour, 0, 255);
  cv::randu(depth, 0, 65535);
  for (const auto& png : {encode(colour), encode(depth)}) {
    cv::Mat out;
    EXPECT_TRUE(io::decodePlainPng(png.data(), png.size(), cv::IMREAD_UNCHANGED, &out));
  }
}

TEST(ImageFile, DoubtfulPngsAreLeftToOpenCv) {
  const int w = 16, h = 9;
  const auto rows = randomRows(w, h, 3, 7);
  const std::vector<uint8_t> good = handPng(w, rows, 8, 2, {4});
  cv::Mat out;
  ASSERT_TRUE(io::decodePlainPng(good.data(), good.size(), cv::IMREAD_COLOR, &out));

  std::map<std::string, std::vector<uint8_t>> doubtful;
  doubtful["transparency"] = handPng(w, rows, 8, 2, {4}, {{"tRNS", {0, 1, 0, 2, 0, 3}}});
  doubtful["palette"] = handPng(w, rows, 8, 2, {4}, {{"PLTE", {1, 2, 3}}});
  doubtful["orientation"] = handPng(w, rows, 8, 2, {4}, {{"eXIf", {'M', 'M', 0, 42}}});
  doubtful["bad filter"] = handPng(w, rows, 8, 2, {5});
  doubtful["truncated"] = std::vector<uint8_t>(good.begin(), good.end() - 20);
  doubtful["no IEND"] = std::vector<uint8_t>(good.begin(), good.end() - 12);
  auto corrupt = good;
  corrupt[corrupt.size() / 2] ^= 0x5a;  // inside the IDAT data: CRC no longer matches
  doubtful["corrupt"] = corrupt;
  auto short_rows = handPng(w, std::vector<std::vector<uint8_t>>(rows.begin(), rows.end() - 1), 8, 2, {4});
  short_rows[8 + 8 + 7] = uint8_t(h);  // IHDR claims one row more than the data holds...
  const uint32_t crc = libdeflate_crc32(0, &short_rows[12], 17);  // ...with a valid CRC
  for (int i = 0; i < 4; ++i) short_rows[29 + i] = uint8_t(crc >> (24 - 8 * i));
  doubtful["too little data"] = short_rows;
  for (const auto& d : doubtful) {
    cv::Mat m;
    EXPECT_FALSE(io::decodePlainPng(d.second.data(), d.second.size(), cv::IMREAD_COLOR, &m)) << d.first;
    EXPECT_TRUE(m.empty()) << d.first;
    expectReadsAsImread(d.second, "doubtful.png", cv::IMREAD_COLOR);
  }
  const std::vector<uint8_t> depth = handPng(w, randomRows(w, h, 2, 8), 16, 0, {1});
  EXPECT_FALSE(io::decodePlainPng(depth.data(), depth.size(), cv::IMREAD_COLOR, &out))
      << "16-bit read as colour is OpenCV's conversion";
  expectReadsAsImread(depth, "depth_as_colour.png", cv::IMREAD_COLOR);
}

namespace {

// Every chunk's CRC rewritten, so that a mutant gets past the checksums to the parser behind.
std::vector<uint8_t> withValidCrcs(std::vector<uint8_t> png) {
  size_t at = 8;
  while (png.size() >= at + 12) {
    const uint32_t length = (uint32_t(png[at]) << 24) | (png[at + 1] << 16) | (png[at + 2] << 8) | png[at + 3];
    if (length > png.size() - at - 12) break;
    const uint32_t crc = libdeflate_crc32(0, &png[at + 4], length + 4);
    for (int i = 0; i < 4; ++i) png[at + 8 + length + i] = uint8_t(crc >> (24 - 8 * i));
    at += 12 + length;
  }
  return png;
}

cv::Mat openCvDecode(const std::vector<uint8_t>& bytes, int flags) {
  try {
    return bytes.empty() ? cv::Mat() : cv::imdecode(bytes, flags);
  } catch (const cv::Exception&) {
    return cv::Mat();
  }
}

}  // namespace

// Differential fuzzing: mutants (their CRCs made valid again) that the fast path accepts decode to
// OpenCV's pixels; the rest are refused without a crash and go to OpenCV.
TEST(ImageFile, MutantsPastTheChecksumsDecodeAsOpenCvDecodesThem) {
  const int w = 13, h = 7;
  const std::vector<std::vector<uint8_t>> valid = {handPng(w, randomRows(w, h, 3, 21), 8, 2, {0, 1, 2, 3, 4}),
                                                   handPng(w, randomRows(w, h, 2, 22), 16, 0, {4, 3, 2, 1, 0})};
  test_support::Mutator mutator(28);
  const int n = test_support::fuzzIterations(400);
  int accepted = 0;
  ::testing::internal::CaptureStderr();  // libpng's messages about the mutants
  for (int i = 0; i < n; ++i) {
    const auto& v = valid[i % valid.size()];
    const std::string m = mutator.mutate(std::string(v.begin(), v.end()));
    const std::vector<uint8_t> mutant = withValidCrcs(std::vector<uint8_t>(m.begin(), m.end()));
    const int flags = i % 2 ? cv::IMREAD_UNCHANGED : cv::IMREAD_COLOR;
    cv::Mat fast;
    if (!io::decodePlainPng(mutant.data(), mutant.size(), flags, &fast)) continue;
    ++accepted;
    EXPECT_TRUE(identical(fast, openCvDecode(mutant, flags))) << "mutant " << i;
  }
  ::testing::internal::GetCapturedStderr();
  EXPECT_GT(accepted, 0) << "no mutant reached the decoder";
  EXPECT_LT(accepted, n) << "no mutant was refused";
}

// Random row data and filter bytes (5-7 are invalid): the fast path decodes exactly what OpenCV
// decodes, and refuses what OpenCV refuses.
TEST(ImageFile, RandomRowsAndFilterBytesDecodeAsOpenCvDecodesThem) {
  std::mt19937 rng(5);
  const int n = test_support::fuzzIterations(400);
  int accepted = 0;
  ::testing::internal::CaptureStderr();
  for (int i = 0; i < n; ++i) {
    const Layout& l = kLayouts[i % (sizeof kLayouts / sizeof kLayouts[0])];
    const int w = 1 + int(rng() % 40), h = 1 + int(rng() % 12);
    std::vector<int> filters(h);
    for (auto& f : filters) f = rng() % 16 == 0 ? 5 + int(rng() % 3) : int(rng() % 5);
    const std::vector<uint8_t> png = handPng(w, randomRows(w, h, l.bpp, rng()), l.depth, l.colour, filters);
    cv::Mat fast;
    const bool ok = io::decodePlainPng(png.data(), png.size(), l.flags, &fast);
    const cv::Mat viaOpenCv = openCvDecode(png, l.flags);
    EXPECT_EQ(ok, !viaOpenCv.empty()) << "case " << i;
    if (ok) {
      ++accepted;
      EXPECT_TRUE(identical(fast, viaOpenCv)) << "case " << i;
    }
  }
  ::testing::internal::GetCapturedStderr();
  EXPECT_GT(accepted, n / 3);
  EXPECT_LT(accepted, n);
}

#endif
