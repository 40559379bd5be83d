// Vocabulary files.
//
// Binary format (all little-endian), version 1:
//   offset  size  field
//        0     8  magic "YSVOCAB\x1a"
//        8     4  version (1)
//       12     4  k (branching factor)
//       16     4  L (levels)
//       20     4  weighting (DBoW2 numbering: 0 tf-idf, 1 tf, 2 idf, 3 binary)
//       24     4  scoring (0 = L1)
//       28     4  descriptor bytes (32)
//       32     4  node count n
//       36     4  word count
//       40     4  flags (0; reserved for compression)
//       44     8  payload size in bytes (= n * 44)
//       52     8  checksum of the payload (see PayloadChecksum)
//       60        payload: parent u32[n], descriptors u8[n][32], weight f64[n], word id u32[n]
//                 (word id 0xffffffff for inner nodes); nodes breadth-first, children contiguous.
// Loading is one read plus memcpy of each array (no parsing), so 10^6 words load in well under
// 0.3 s; the checksum catches truncated or corrupted files.
//
// ORB-SLAM2 text format (ORBvoc.txt, DBoW2's saveToTextFile):
//   line 1: "k L scoring weighting"
//   then one line per node 1..n-1 in order: "parent_id is_leaf d0 d1 ... d31 weight"
#include "yolo_slam/common/error.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <sys/stat.h>

namespace yolo_slam {
namespace vocabulary {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "vocabulary files are little-endian");

namespace {

constexpr char kMagic[8] = {'Y', 'S', 'V', 'O', 'C', 'A', 'B', '\x1a'};
constexpr uint32_t kVersion = 1;
constexpr size_t kHeaderBytes = 60;
constexpr size_t kBytesPerNode = 4 + kDescriptorBytes + 8 + 4;

// FNV-1a (64-bit offset basis and prime) applied to the payload's little-endian 64-bit words,
// then to the remaining tail bytes one by one. Word-wise rather than byte-wise keeps it at
// about 10 ms for a 50 MB payload. Streaming, so arrays can be hashed as they are read.
class PayloadChecksum {
 public:
  void update(const uint8_t* p, size_t n) {
    while (n > 0 && carry_n_ > 0) {  // complete a word started by the previous chunk
      carry_[carry_n_++] = *p++;
      --n;
      if (carry_n_ == 8) {
        word(carry_);
        carry_n_ = 0;
      }
    }
    size_t i = 0;
    for (; i + 8 <= n; i += 8) word(p + i);
    for (; i < n; ++i) carry_[carry_n_++] = p[i];
  }
  uint64_t finish() {
    for (size_t i = 0; i < carry_n_; ++i) {
      h_ ^= carry_[i];
      h_ *= kPrime;
    }
    carry_n_ = 0;
    return h_;
  }

 private:
  static constexpr uint64_t kPrime = 0x100000001b3ull;
  void word(const uint8_t* p) {
    uint64_t w;
    std::memcpy(&w, p, 8);
    h_ ^= w;
    h_ *= kPrime;
  }
  uint64_t h_ = 0xcbf29ce484222325ull;
  uint8_t carry_[8] = {0};
  size_t carry_n_ = 0;
};

template <typename T>
void put(std::vector<uint8_t>& out, size_t& off, const T& v) {
  std::memcpy(out.data() + off, &v, sizeof(T));
  off += sizeof(T);
}

template <typename T>
T get(const uint8_t* p, size_t off) {
  T v;
  std::memcpy(&v, p + off, sizeof(T));
  return v;
}

void writeAtomically(const std::string& path, const void* data, size_t size) {
  const std::string tmp = path + ".tmp";
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f)
    throw Error(path + ": cannot write vocabulary (" + std::strerror(errno) +
                "); check that the folder exists and is writable");
  const bool ok = std::fwrite(data, 1, size, f) == size;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) {
    std::remove(tmp.c_str());
    throw Error(path + ": writing the vocabulary failed (disk full?)");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw Error(path + ": cannot rename " + tmp + " into place (" + std::strerror(errno) + ")");
  }
}

std::vector<uint8_t> readWholeFile(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f)
    throw Error(path + ": cannot open vocabulary (" + std::strerror(errno) +
                "); pass the path of a vocabulary file (e.g. vocab/yolo_slam_orb_k10_L4.vocab) or "
                "train one with yolo_slam_train_vocab");
  std::vector<uint8_t> buf;
  if (std::fseek(f, 0, SEEK_END) == 0) {
    const long size = std::ftell(f);
    if (size > 0) {
      buf.resize(static_cast<size_t>(size));
      std::rewind(f);
      const size_t got = std::fread(buf.data(), 1, buf.size(), f);
      buf.resize(got);
    }
  }
  std::fclose(f);
  return buf;
}

Weighting parseWeighting(long v, const std::string& where) {
  if (v < 0 || v > 3)
    throw Error(where + ": unsupported weighting type " + std::to_string(v) +
                " (0 tf-idf, 1 tf, 2 idf, 3 binary)");
  return static_cast<Weighting>(v);
}

Scoring parseScoring(long v, const std::string& where) {
  if (v != 0)
    throw Error(where + ": unsupported scoring type " + std::to_string(v) +
                " (only 0 = L1, the scoring ORB-SLAM2 uses, is supported); retrain or convert "
                "the vocabulary with L1 scoring");
  return Scoring::L1;
}

struct FileCloser {
  void operator()(FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<FILE, FileCloser>;

FilePtr openForReading(const std::string& path) {
  FilePtr f(std::fopen(path.c_str(), "rb"));
  if (!f)
    throw Error(path + ": cannot open vocabulary (" + std::strerror(errno) +
                "); pass the path of a vocabulary file (e.g. vocab/yolo_slam_orb_k10_L4.vocab) or "
                "train one with yolo_slam_train_vocab");
  return f;
}

bool startsWithMagic(const std::string& path) {
  FilePtr f = openForReading(path);
  char head[sizeof(kMagic)];
  return std::fread(head, 1, sizeof(head), f.get()) == sizeof(head) &&
         std::memcmp(head, kMagic, sizeof(kMagic)) == 0;
}

// Reads the header, then each node array straight into its vector (no intermediate buffer),
// hashing as it goes.
std::shared_ptr<Vocabulary> readBinary(const std::string& path) {
  FilePtr f = openForReading(path);
  uint8_t h[kHeaderBytes];
  const size_t got = std::fread(h, 1, kHeaderBytes, f.get());
  if (got < sizeof(kMagic) || std::memcmp(h, kMagic, sizeof(kMagic)) != 0)
    throw Error(path + ": not a yolo_slam binary vocabulary (bad magic)");
  if (got < kHeaderBytes)
    throw Error(path + ": truncated vocabulary header (" + std::to_string(got) +
                " bytes); the file is damaged, regenerate it (see vocab/README.md)");
  const uint32_t version = get<uint32_t>(h, 8);
  if (version != kVersion)
    throw Error(path + ": vocabulary format version " + std::to_string(version) +
                " is not supported (this build reads version " + std::to_string(kVersion) + ")");
  const uint32_t k = get<uint32_t>(h, 12), levels = get<uint32_t>(h, 16);
  const Weighting weighting = parseWeighting(get<uint32_t>(h, 20), path);
  const Scoring scoring = parseScoring(get<uint32_t>(h, 24), path);
  const uint32_t dbytes = get<uint32_t>(h, 28);
  const uint32_t n = get<uint32_t>(h, 32), words = get<uint32_t>(h, 36), flags = get<uint32_t>(h, 40);
  const uint64_t payload = get<uint64_t>(h, 44), checksum = get<uint64_t>(h, 52);
  if (dbytes != kDescriptorBytes)
    throw Error(path + ": descriptor size " + std::to_string(dbytes) + " bytes, expected 32 (ORB)");
  if (flags != 0) throw Error(path + ": unknown vocabulary flags " + std::to_string(flags));
  if (payload != static_cast<uint64_t>(n) * kBytesPerNode)
    throw Error(path + ": header is inconsistent (payload size does not match node count)");
  struct stat st {};
  if (::fstat(::fileno(f.get()), &st) != 0 || static_cast<uint64_t>(st.st_size) != kHeaderBytes + payload)
    throw Error(path + ": vocabulary is truncated or has trailing bytes (" +
                std::to_string(static_cast<long long>(st.st_size) - static_cast<long long>(kHeaderBytes)) +
                " payload bytes, header says " + std::to_string(payload) +
                "); regenerate it (see vocab/README.md)");
  std::vector<uint32_t> parents(n), word_ids(n);
  std::vector<uint8_t> desc(static_cast<size_t>(n) * kDescriptorBytes);
  std::vector<double> weights(n);
  PayloadChecksum sum;
  auto readArray = [&](void* dst, size_t bytes) {
    if (std::fread(dst, 1, bytes, f.get()) != bytes)
      throw Error(path + ": vocabulary is truncated; regenerate it (see vocab/README.md)");
    sum.update(static_cast<const uint8_t*>(dst), bytes);
  };
  readArray(parents.data(), n * 4ull);
  readArray(desc.data(), desc.size());
  readArray(weights.data(), n * 8ull);
  readArray(word_ids.data(), n * 4ull);
  if (sum.finish() != checksum)
    throw Error(path + ": vocabulary checksum mismatch: the file is corrupt; regenerate it (see "
                "vocab/README.md)");
  auto v = Vocabulary::fromNodes(static_cast<int>(k), static_cast<int>(levels), weighting, scoring,
                                 std::move(parents), std::move(desc), std::move(weights),
                                 std::move(word_ids), path);
  if (v->size() != words)
    throw Error(path + ": header says " + std::to_string(words) + " words, the tree has " +
                std::to_string(v->size()));
  return v;
}

// `n` bytes at `p` as a message may quote them: non-printable bytes as '?'.
std::string quotable(const char* p, size_t n) {
  std::string out(p, n);
  for (char& c : out)
    if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
  return out;
}

// A text vocabulary is ASCII digits and spaces; a NUL or another control byte in its first
// kibibytes means the file is binary data of some other kind.
void checkLooksLikeText(const std::vector<uint8_t>& buf, const std::string& path) {
  constexpr size_t kSniffBytes = 4096;
  const size_t n = std::min(buf.size(), kSniffBytes);
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = buf[i];
    if (c == '\n' || c == '\r' || c == '\t' || std::isprint(c)) continue;
    throw Error(path + ": not a vocabulary: neither a yolo_slam binary vocabulary (it would start "
                "with YSVOCAB) nor an ORB-SLAM2 text vocabulary (byte " + std::to_string(i) +
                " is binary data); pass a .vocab written by yolo_slam_train_vocab or ORBvoc.txt");
  }
}

// Strict number parsing on one text line; reports file:line on any problem.
struct LineParser {
  const char* cur;
  const char* end;
  const std::string& where;

  [[noreturn]] void fail(const std::string& what) const { throw Error(where + ": " + what); }

  void skipSpace() {
    while (cur < end && (*cur == ' ' || *cur == '\t' || *cur == '\r')) ++cur;
  }
  bool atEnd() {
    skipSpace();
    return cur >= end;
  }
  long integer(const char* field) {
    skipSpace();
    if (cur >= end) fail(std::string("missing ") + field);
    char* stop = nullptr;
    errno = 0;
    const long v = std::strtol(cur, &stop, 10);
    if (stop == cur || errno != 0 || (stop < end && !std::isspace(static_cast<unsigned char>(*stop))))
      fail(std::string("bad ") + field + " '" + quotable(cur, std::min<size_t>(end - cur, 16)) + "'");
    cur = stop;
    return v;
  }
  double real(const char* field) {
    skipSpace();
    if (cur >= end) fail(std::string("missing ") + field);
    char* stop = nullptr;
    const double v = std::strtod(cur, &stop);
    if (stop == cur || (stop < end && !std::isspace(static_cast<unsigned char>(*stop))) || !std::isfinite(v))
      fail(std::string("bad ") + field + " '" + quotable(cur, std::min<size_t>(end - cur, 16)) + "'");
    cur = stop;
    return v;
  }
};

// ORB-SLAM2 text layout: the header line 'k L scoring weighting'.
struct TextHeader {
  int k = 0, levels = 0;
  Weighting weighting = Weighting::TfIdf;
  Scoring scoring = Scoring::L1;
};

TextHeader parseTextHeader(LineParser& lp, const std::string& where) {
  TextHeader h;
  h.k = static_cast<int>(lp.integer("k"));
  h.levels = static_cast<int>(lp.integer("L"));
  h.scoring = parseScoring(lp.integer("scoring type"), where);
  h.weighting = parseWeighting(lp.integer("weighting type"), where);
  if (!lp.atEnd()) lp.fail("unexpected text after 'k L scoring weighting'");
  if (h.k < 2 || h.levels < 1) lp.fail("invalid k=" + std::to_string(h.k) + " L=" + std::to_string(h.levels));
  return h;
}

// The nodes read so far (node 0 the root, which has no descriptor) and where each came from.
struct TextNodes {
  std::vector<uint32_t> parents{0};
  std::vector<uint8_t> desc = std::vector<uint8_t>(kDescriptorBytes, 0);
  std::vector<double> weights{0.0};
  std::vector<uint8_t> declared_leaf{0};
  std::vector<size_t> node_line{0};
};

// One node line: 'parent is_leaf byte x 32 weight'.
void parseNodeLine(LineParser& lp, size_t line_no, TextNodes& t) {
  const long pid = lp.integer("parent id");
  const long leaf = lp.integer("is_leaf flag");
  if (pid < 0 || static_cast<size_t>(pid) >= t.parents.size())
    lp.fail("parent id " + std::to_string(pid) + " does not name an earlier node (nodes so far: " +
            std::to_string(t.parents.size()) + ")");
  if (leaf != 0 && leaf != 1) lp.fail("is_leaf must be 0 or 1, got " + std::to_string(leaf));
  if (t.declared_leaf[pid])
    lp.fail("parent " + std::to_string(pid) + " was declared a leaf (line " +
            std::to_string(t.node_line[pid]) + ")");
  for (int b = 0; b < kDescriptorBytes; ++b) {
    const long v = lp.integer("descriptor byte");
    if (v < 0 || v > 255) lp.fail("descriptor byte " + std::to_string(v) + " out of 0..255");
    t.desc.push_back(static_cast<uint8_t>(v));
  }
  const double w = lp.real("weight");
  if (!lp.atEnd()) lp.fail("unexpected text after the weight (expected 32 descriptor bytes then one weight)");
  t.parents.push_back(static_cast<uint32_t>(pid));
  t.weights.push_back(w);
  t.declared_leaf.push_back(static_cast<uint8_t>(leaf));
  t.node_line.push_back(line_no);
}

// A node declared inner must have children (else it would silently swallow descriptors).
void checkInnerNodesHaveChildren(const TextNodes& t, const std::string& path) {
  std::vector<uint8_t> has_child(t.parents.size(), 0);
  for (size_t i = 1; i < t.parents.size(); ++i) has_child[t.parents[i]] = 1;
  for (size_t i = 1; i < t.parents.size(); ++i)
    if (!t.declared_leaf[i] && !has_child[i])
      throw Error(path + ":" + std::to_string(t.node_line[i]) + ": node " + std::to_string(i) +
                  " is declared inner (is_leaf 0) but has no children");
}

}  // namespace

std::shared_ptr<Vocabulary> Vocabulary::loadBinary(const std::string& path) { return readBinary(path); }

std::shared_ptr<Vocabulary> Vocabulary::load(const std::string& path) {
  return startsWithMagic(path) ? readBinary(path) : loadText(path);
}

std::shared_ptr<Vocabulary> Vocabulary::loadText(const std::string& path) {
  std::vector<uint8_t> buf = readWholeFile(path);
  checkLooksLikeText(buf, path);
  const size_t text_bytes = buf.size();
  buf.push_back('\0');  // strtol/strtod stop here at the latest when the last line has no newline
  const char* p = reinterpret_cast<const char*>(buf.data());
  const char* end = p + text_bytes;
  size_t line_no = 0;
  TextHeader header;
  bool have_header = false;
  TextNodes nodes;
  while (p < end) {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', end - p));
    const char* le = nl ? nl : end;
    ++line_no;
    const std::string where = path + ":" + std::to_string(line_no);
    LineParser lp{p, le, where};
    p = nl ? nl + 1 : end;
    if (lp.atEnd()) continue;  // blank lines (e.g. a trailing newline)
    if (!have_header) {
      header = parseTextHeader(lp, where);
      have_header = true;
    } else {
      parseNodeLine(lp, line_no, nodes);
    }
  }
  if (!have_header) throw Error(path + ": empty vocabulary text file (expected 'k L scoring weighting')");
  checkInnerNodesHaveChildren(nodes, path);
  return fromNodes(header.k, header.levels, header.weighting, header.scoring, nodes.parents, nodes.desc,
                   nodes.weights, {}, path);
}

void Vocabulary::save(const std::string& path) const {
  const size_t n = parent_.size();
  const size_t payload = n * kBytesPerNode;
  std::vector<uint8_t> out(kHeaderBytes + payload);
  size_t off = 0;
  std::memcpy(out.data(), kMagic, sizeof(kMagic));
  off += sizeof(kMagic);
  put<uint32_t>(out, off, kVersion);
  put<uint32_t>(out, off, static_cast<uint32_t>(k_));
  put<uint32_t>(out, off, static_cast<uint32_t>(levels_));
  put<uint32_t>(out, off, static_cast<uint32_t>(weighting_));
  put<uint32_t>(out, off, static_cast<uint32_t>(scoring_));
  put<uint32_t>(out, off, static_cast<uint32_t>(kDescriptorBytes));
  put<uint32_t>(out, off, static_cast<uint32_t>(n));
  put<uint32_t>(out, off, static_cast<uint32_t>(size()));
  put<uint32_t>(out, off, 0u);
  put<uint64_t>(out, off, static_cast<uint64_t>(payload));
  const size_t checksum_off = off;
  off += 8;
  std::memcpy(out.data() + off, parent_.data(), n * 4);
  off += n * 4;
  std::memcpy(out.data() + off, desc_.data(), desc_.size());
  off += desc_.size();
  std::memcpy(out.data() + off, weight_.data(), n * 8);
  off += n * 8;
  std::memcpy(out.data() + off, word_of_node_.data(), n * 4);
  PayloadChecksum hasher;
  hasher.update(out.data() + kHeaderBytes, payload);
  const uint64_t sum = hasher.finish();
  std::memcpy(out.data() + checksum_off, &sum, 8);
  writeAtomically(path, out.data(), out.size());
}

void Vocabulary::saveText(const std::string& path) const {
  // DBoW2 numbers nodes in file order and words in leaf order: write nodes in our order and
  // words in the order of their ids, which our word numbering (leaves in node order) matches
  // only if the ids are ascending in node order -- true for trained and text-loaded trees.
  std::ostringstream os;
  os.precision(17);
  os << k_ << ' ' << levels_ << ' ' << static_cast<int>(scoring_) << ' ' << static_cast<int>(weighting_)
     << '\n';
  for (size_t i = 1; i < parent_.size(); ++i) {
    os << parent_[i] << ' ' << (n_children_[i] == 0 ? 1 : 0);
    const uint8_t* d = nodeDescriptor(static_cast<NodeId>(i));
    for (int b = 0; b < kDescriptorBytes; ++b) os << ' ' << static_cast<int>(d[b]);
    os << ' ' << weight_[i] << '\n';
  }
  const std::string s = os.str();
  writeAtomically(path, s.data(), s.size());
}

}  // namespace vocabulary
}  // namespace yolo_slam
