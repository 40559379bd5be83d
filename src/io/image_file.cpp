#include "yolo_slam/io/image_file.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <vector>

#ifdef YOLO_SLAM_HAVE_LIBDEFLATE
#include <libdeflate.h>
#endif

namespace yolo_slam {
namespace io {
namespace {

// Files larger than this are left to cv::imread, which reads only what it needs of them.
constexpr std::streamoff kMaxBufferedFile = std::streamoff(1) << 30;

// The whole file into `bytes`; false when it cannot be opened or read, is empty or too large.
bool readBytes(const std::string& path, std::vector<uint8_t>& bytes) {
  bytes.clear();
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = f ? std::streamoff(f.tellg()) : std::streamoff(0);
  if (size <= 0 || size > kMaxBufferedFile) return false;
  bytes.resize(static_cast<size_t>(size));
  f.seekg(0);
  if (f.read(reinterpret_cast<char*>(bytes.data()), size)) return true;
  bytes.clear();
  return false;
}

// OpenCV's decoders report most failures with an empty Mat, some by throwing: both are empty here.
template <typename Decode>
cv::Mat emptyOnException(Decode decode) {
  try {
    return decode();
  } catch (const cv::Exception&) {
    return cv::Mat();
  }
}

}  // namespace

cv::Mat readImage(const std::string& path, int flags) {
  // Buffers reused from image to image: a frame's megabyte is not allocated and faulted in anew.
  thread_local std::vector<uint8_t> bytes;
  if (!readBytes(path, bytes)) return emptyOnException([&] { return cv::imread(path, flags); });
  cv::Mat out;
  if (decodePlainPng(bytes.data(), bytes.size(), flags, &out)) return out;
  const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1, bytes.data());
  return emptyOnException([&] { return cv::imdecode(encoded, flags); });
}

#ifndef YOLO_SLAM_HAVE_LIBDEFLATE

bool decodePlainPng(const uint8_t*, size_t, int, cv::Mat*) { return false; }

#else

namespace {

constexpr uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
constexpr size_t kChunkOverhead = 12;  // length, type, CRC
constexpr size_t kIhdrLength = 13;
constexpr uint8_t kGrey = 0, kRgb = 2;
// Larger images go to OpenCV, whose own pixel limit then applies.
constexpr size_t kMaxFastPathBytes = size_t(1) << 30;

uint32_t bigEndian32(const uint8_t* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}

struct PngLayout {
  uint32_t width = 0, height = 0;
  uint8_t bit_depth = 0, colour_type = 0;
  std::vector<uint8_t>* idat = nullptr;  // the zlib stream, IDAT chunks joined
  size_t channels() const { return colour_type == kRgb ? 3 : 1; }
  size_t pixelBytes() const { return channels() * bit_depth / 8; }
  size_t rowBytes() const { return size_t(width) * pixelBytes(); }
};

bool plainHeader(const uint8_t* d, PngLayout& png) {
  png.width = bigEndian32(d);
  png.height = bigEndian32(d + 4);
  png.bit_depth = d[8];
  png.colour_type = d[9];
  const bool compression_filter_interlace_plain = d[10] == 0 && d[11] == 0 && d[12] == 0;
  const bool layout = (png.colour_type == kRgb && png.bit_depth == 8) ||
                      (png.colour_type == kGrey && (png.bit_depth == 8 || png.bit_depth == 16));
  return compression_filter_interlace_plain && layout && png.width > 0 && png.height > 0 &&
         png.width < (1u << 31) && png.height < (1u << 31) &&
         (png.rowBytes() + 1) * png.height <= kMaxFastPathBytes;
}

// Walks the chunks, checking every CRC. False on anything libpng would treat differently from
// plain pixels (a palette, transparency, an EXIF orientation) or would reject.
bool parsePlainPng(const uint8_t* data, size_t size, PngLayout& png) {
  if (size < sizeof(kPngSignature) || std::memcmp(data, kPngSignature, sizeof(kPngSignature)) != 0) return false;
  size_t at = sizeof(kPngSignature);
  bool first = true;
  while (size - at >= kChunkOverhead) {
    const uint32_t length = bigEndian32(data + at);
    if (length > size - at - kChunkOverhead) return false;
    const uint8_t* type = data + at + 4;
    const uint8_t* body = type + 4;
    if (libdeflate_crc32(0, type, length + 4) != bigEndian32(body + length)) return false;
    const std::string name(reinterpret_cast<const char*>(type), 4);
    at += kChunkOverhead + length;
    if (first != (name == "IHDR")) return false;
    first = false;
    if (name == "IHDR") {
      if (length != kIhdrLength || !plainHeader(body, png)) return false;
    } else if (name == "IDAT") {
      png.idat->insert(png.idat->end(), body, body + length);
    } else if (name == "IEND") {
      return !png.idat->empty();
    } else if (name == "tRNS" || name == "eXIf" || (name[0] & 0x20) == 0) {
      return false;  // transparency, orientation, or a critical chunk such as PLTE
    }
  }
  return false;  // no IEND: truncated
}

// The Paeth predictor without branches (the choice depends on the data, which a branch predictor
// cannot guess); ties go to left, then up, as the specification orders them.
inline uint8_t paeth(int left, int up, int up_left) {
  const int pa = std::abs(up - up_left), pb = std::abs(left - up_left), pc = std::abs(left + up - 2 * up_left);
  const int nearer = pb < pa ? up : left;
  const int nearer_distance = pb < pa ? pb : pa;
  return static_cast<uint8_t>(pc < nearer_distance ? up_left : nearer);
}

// The pixel size a template argument: the compiler keeps the bytes of one pixel in registers.
template <size_t kBpp>
void unpaeth(uint8_t* row, const uint8_t* prev, size_t n) {
  for (size_t i = 0; i < kBpp; ++i) row[i] = uint8_t(row[i] + prev[i]);
  for (size_t i = kBpp; i < n; i += kBpp)
    for (size_t k = 0; k < kBpp; ++k)
      row[i + k] = uint8_t(row[i + k] + paeth(row[i + k - kBpp], prev[i + k], prev[i + k - kBpp]));
}

// Undoes one row's filter in place (PNG specification, section 9). `prev` is the row above,
// already unfiltered, or zeros for the first row.
bool unfilterRow(uint8_t filter, uint8_t* row, const uint8_t* prev, size_t n, size_t bpp) {
  switch (filter) {
    case 0: return true;
    case 1:
      for (size_t i = bpp; i < n; ++i) row[i] = uint8_t(row[i] + row[i - bpp]);
      return true;
    case 2:
      for (size_t i = 0; i < n; ++i) row[i] = uint8_t(row[i] + prev[i]);
      return true;
    case 3:
      for (size_t i = 0; i < bpp; ++i) row[i] = uint8_t(row[i] + (prev[i] >> 1));
      for (size_t i = bpp; i < n; ++i) row[i] = uint8_t(row[i] + ((row[i - bpp] + prev[i]) >> 1));
      return true;
    case 4:
      switch (bpp) {
        case 1: unpaeth<1>(row, prev, n); return true;
        case 2: unpaeth<2>(row, prev, n); return true;
        case 3: unpaeth<3>(row, prev, n); return true;
        default: return false;
      }
    default: return false;
  }
}

// Inflates the joined IDAT data into `raw` (each row: filter byte + pixels) and unfilters it.
bool inflateAndUnfilter(const PngLayout& png, std::vector<uint8_t>& raw) {
  using Decompressor = std::unique_ptr<libdeflate_decompressor, void (*)(libdeflate_decompressor*)>;
  thread_local Decompressor inflater(libdeflate_alloc_decompressor(), libdeflate_free_decompressor);
  if (!inflater) return false;
  const size_t row = png.rowBytes(), stride = row + 1;
  raw.resize(stride * png.height);
  size_t produced = 0;
  if (libdeflate_zlib_decompress(inflater.get(), png.idat->data(), png.idat->size(), raw.data(), raw.size(),
                                 &produced) != LIBDEFLATE_SUCCESS ||
      produced != raw.size())
    return false;
  const std::vector<uint8_t> zeros(row, 0);
  for (size_t r = 0; r < png.height; ++r) {
    uint8_t* line = raw.data() + r * stride;
    const uint8_t* prev = r == 0 ? zeros.data() : line - stride + 1;
    if (!unfilterRow(line[0], line + 1, prev, row, png.pixelBytes())) return false;
  }
  return true;
}

// The unfiltered rows as the cv::Mat imread gives: BGR for colour, native-endian 16-bit depth.
bool toMat(const PngLayout& png, std::vector<uint8_t>& raw, int flags, cv::Mat* out) {
  const int rows = static_cast<int>(png.height), cols = static_cast<int>(png.width);
  const size_t stride = png.rowBytes() + 1;
  if (png.bit_depth == 16) {
    if (flags != cv::IMREAD_UNCHANGED) return false;
    cv::Mat m(rows, cols, CV_16UC1);
    for (int r = 0; r < rows; ++r) {
      const uint8_t* s = raw.data() + r * stride + 1;
      uint16_t* d = m.ptr<uint16_t>(r);
      for (int c = 0; c < cols; ++c) d[c] = uint16_t((s[2 * c] << 8) | s[2 * c + 1]);
    }
    *out = m;
    return true;
  }
  const cv::Mat pixels(rows, cols, png.colour_type == kRgb ? CV_8UC3 : CV_8UC1, raw.data() + 1, stride);
  if (png.colour_type == kRgb)
    cv::cvtColor(pixels, *out, cv::COLOR_RGB2BGR);
  else if (flags == cv::IMREAD_COLOR)
    cv::cvtColor(pixels, *out, cv::COLOR_GRAY2BGR);
  else
    *out = pixels.clone();
  return true;
}

}  // namespace

bool decodePlainPng(const uint8_t* data, size_t size, int flags, cv::Mat* out) {
  if (flags != cv::IMREAD_COLOR && flags != cv::IMREAD_UNCHANGED) return false;
  thread_local std::vector<uint8_t> idat, raw;
  idat.clear();
  PngLayout png;
  png.idat = &idat;
  if (!parsePlainPng(data, size, png)) return false;
  if (png.bit_depth == 16 && flags != cv::IMREAD_UNCHANGED) return false;
  return inflateAndUnfilter(png, raw) && toMat(png, raw, flags, out);
}

#endif

}  // namespace io
}  // namespace yolo_slam
