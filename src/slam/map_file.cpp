#include "yolo_slam/slam/map_file.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/features/feature_frame.h"
#include "yolo_slam/io/atomic_file.h"
#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <cereal/archives/portable_binary.hpp>
#include <cereal/types/array.hpp>
#include <cereal/types/string.hpp>
#include <cereal/types/utility.hpp>
#include <cereal/types/vector.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>
#include <type_traits>
#include <unordered_map>

namespace yolo_slam {
namespace slam {
namespace {

constexpr std::array<char, 8> kMagic = {'Y', 'S', 'M', 'A', 'P', '\r', '\n', '\0'};
constexpr size_t kDescriptorBytes = 32;
constexpr long kNone = -1;  // no parent / reference keyframe
// Camera parameters equal up to rounding of their text form in the settings file.
constexpr double kCameraTolerance = 1e-9;
constexpr const char* kRebuildHint = "rebuild the map with yolo_slam_run --save-map";
// FNV-1a, 64-bit offset basis and prime.
constexpr uint64_t kFnvBasis = 1469598103934665603ull;
constexpr uint64_t kFnvPrime = 1099511628211ull;

// ---- counts bounded by the payload ----

// A count in a file that passed the checksum can still be wrong (a writer bug, a crafted file);
// cereal would allocate it before reading. Counts are therefore checked against the payload's
// size (every element takes at least one byte of it). Set by parsePayload while it reads.
thread_local size_t t_payload_bytes = 0;

// A vector member written as cereal writes it, read with its count checked.
template <class T>
struct Counted {
  std::vector<T>& v;
};
template <class T>
Counted<T> counted(std::vector<T>& v) {
  return {v};
}

template <class Ar, class T>
void save(Ar& ar, const Counted<T>& c) {
  ar(c.v);
}

template <class Ar, class T>
void load(Ar& ar, Counted<T>& c) {
  cereal::size_type n = 0;
  ar(cereal::make_size_tag(n));
  const size_t bytes_each = std::is_arithmetic<T>::value ? sizeof(T) : 1;
  if (n > t_payload_bytes / bytes_each)
    throw cereal::Exception("a count of " + std::to_string(n) + " exceeds the payload");
  c.v.clear();
  if constexpr (std::is_arithmetic<T>::value) {
    c.v.resize(static_cast<size_t>(n));
    ar(cereal::binary_data(c.v.data(), static_cast<size_t>(n) * sizeof(T)));
  } else {
    // Grown as elements are read: a count larger than what follows fails at the end of the data.
    for (cereal::size_type i = 0; i < n; ++i) {
      c.v.emplace_back();
      ar(c.v.back());
    }
  }
}

// A bool member as the byte cereal writes for it, read back only as 0 or 1 (another byte value
// in a bool is undefined behaviour).
struct Flag {
  bool& b;
};

template <class Ar>
void save(Ar& ar, const Flag& f) {
  ar(static_cast<uint8_t>(f.b ? 1 : 0));
}

template <class Ar>
void load(Ar& ar, Flag& f) {
  uint8_t v = 0;
  ar(v);
  if (v > 1) throw cereal::Exception("a flag byte is " + std::to_string(v) + ", neither 0 nor 1");
  f.b = v == 1;
}

// ---- file records: plain values, fixed-width types, one cereal serialize() each ----

struct Header {
  std::array<char, 8> magic = kMagic;
  uint32_t version = kMapFileFormatVersion;
  uint64_t payload_size = 0;
  uint64_t payload_checksum = 0;
  template <class Ar>
  void serialize(Ar& ar) { ar(magic, version, payload_size, payload_checksum); }
};

using PoseRecord = std::array<double, 12>;  // 3 x 4 [R | t], row-major

struct CameraRecord {
  std::array<double, 4> intrinsics{};   // fx fy cx cy
  std::array<double, 5> distortion{};   // k1 k2 p1 p2 k3
  int32_t width = 0, height = 0;
  double bf = 0;
  int32_t orb_levels = 0;
  double orb_scale_factor = 0;
  template <class Ar>
  void serialize(Ar& ar) { ar(intrinsics, distortion, width, height, bf, orb_levels, orb_scale_factor); }
};

struct KeyPointRecord {
  float x = 0, y = 0, size = 0, angle = 0, response = 0;
  int32_t octave = 0, class_id = 0;
  template <class Ar>
  void serialize(Ar& ar) { ar(x, y, size, angle, response, octave, class_id); }
};

struct KeyFrameRecord {
  int64_t id = 0, frame_id = 0;
  double stamp = 0;
  PoseRecord T_cw{}, T_cp{};
  std::vector<KeyPointRecord> keypoints;
  std::vector<uint8_t> descriptors;  // N x 32
  std::vector<float> depth, right_u;
  std::vector<uint8_t> dynamic;
  std::vector<int8_t> motion;
  std::vector<std::pair<int64_t, int32_t>> connections;  // keyframe id, weight
  int64_t parent = kNone;
  std::vector<int64_t> loop_edges;
  bool first_connection = true, not_erase = false, is_origin = false;
  template <class Ar>
  void serialize(Ar& ar) {
    ar(id, frame_id, stamp, T_cw, T_cp, counted(keypoints), counted(descriptors), counted(depth), counted(right_u),
       counted(dynamic), counted(motion));
    ar(counted(connections), parent, counted(loop_edges), Flag{first_connection}, Flag{not_erase}, Flag{is_origin});
  }
};

struct MapPointRecord {
  int64_t id = 0;
  std::array<double, 3> Xw{}, normal{};
  double min_dist = 0, max_dist = 0;
  std::vector<uint8_t> descriptor;
  std::vector<std::pair<int64_t, uint32_t>> observations;  // keyframe id, keypoint index
  int64_t ref_kf = kNone, first_kf_id = kNone, first_frame_id = kNone;
  int32_t visible = 0, found = 0;
  bool dynamic = false;
  template <class Ar>
  void serialize(Ar& ar) {
    ar(id, Xw, normal, min_dist, max_dist, counted(descriptor), counted(observations), ref_kf, first_kf_id,
       first_frame_id);
    ar(visible, found, Flag{dynamic});
  }
};

struct Payload {
  CameraRecord camera;
  uint64_t vocabulary = 0;  // vocabularyChecksum, 0: built without vocabulary
  int64_t next_kf_id = 0, next_point_id = 0;
  std::vector<KeyFrameRecord> keyframes;
  std::vector<MapPointRecord> points;
  template <class Ar>
  void serialize(Ar& ar) { ar(camera, vocabulary, next_kf_id, next_point_id, counted(keyframes), counted(points)); }
};

// ---- checksums ----

uint64_t fnv1a(const uint8_t* data, size_t n, uint64_t h = kFnvBasis) {
  for (size_t i = 0; i < n; ++i) h = (h ^ data[i]) * kFnvPrime;
  return h;
}

template <class T>
uint64_t fnv1aValue(const T& v, uint64_t h) {
  return fnv1a(reinterpret_cast<const uint8_t*>(&v), sizeof v, h);
}

// ---- conversion of the map objects to records ----

PoseRecord toRecord(const Pose& T) {
  PoseRecord r{};
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col) r[4 * row + col] = T.matrix()(row, col);
  return r;
}

Pose fromRecord(const PoseRecord& r) {
  Pose T = Pose::Identity();
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col) T.matrix()(row, col) = r[4 * row + col];
  return T;
}

std::vector<uint8_t> matBytes(const cv::Mat& m) {
  if (m.empty()) return {};
  const cv::Mat c = m.isContinuous() ? m : m.clone();
  return std::vector<uint8_t>(c.data, c.data + c.total() * c.elemSize());
}

CameraRecord cameraRecord(const MapFileContext& ctx) {
  const CameraModel& c = ctx.camera;
  CameraRecord r;
  r.intrinsics = {c.fx, c.fy, c.cx, c.cy};
  r.distortion = {c.k1, c.k2, c.p1, c.p2, c.k3};
  r.width = c.width;
  r.height = c.height;
  r.bf = c.bf;
  r.orb_levels = ctx.orb_levels;
  r.orb_scale_factor = ctx.orb_scale_factor;
  return r;
}

KeyFrameRecord keyFrameRecord(const KeyFrame& kf) {
  KeyFrameRecord r;
  r.id = kf.id;
  r.frame_id = kf.frame_id;
  r.stamp = kf.f.stamp;
  r.T_cw = toRecord(kf.Tcw());
  r.T_cp = toRecord(kf.T_cp);
  for (const cv::KeyPoint& k : kf.f.kps)
    r.keypoints.push_back({k.pt.x, k.pt.y, k.size, k.angle, k.response, k.octave, k.class_id});
  r.descriptors = matBytes(kf.f.descriptors);
  r.depth = kf.f.depth;
  r.right_u = kf.f.right_u;
  r.dynamic = kf.f.dynamic;
  r.motion = kf.f.motion;
  for (const auto& c : kf.connections)
    if (!c.first->bad) r.connections.emplace_back(c.first->id, c.second);
  r.parent = kf.parent && !kf.parent->bad ? kf.parent->id : kNone;
  for (const auto& l : kf.loop_edges)
    if (!l->bad) r.loop_edges.push_back(l->id);
  r.first_connection = kf.first_connection;
  r.not_erase = kf.not_erase;
  r.is_origin = kf.is_origin;
  return r;
}

MapPointRecord mapPointRecord(const MapPoint& mp) {
  MapPointRecord r;
  r.id = mp.id;
  r.Xw = {mp.Xw.x(), mp.Xw.y(), mp.Xw.z()};
  r.normal = {mp.normal.x(), mp.normal.y(), mp.normal.z()};
  r.min_dist = mp.min_dist;
  r.max_dist = mp.max_dist;
  r.descriptor = matBytes(mp.descriptor);
  for (const auto& o : mp.observations)
    if (!o.first->bad) r.observations.emplace_back(o.first->id, static_cast<uint32_t>(o.second));
  r.ref_kf = mp.ref_kf ? mp.ref_kf->id : kNone;
  r.first_kf_id = mp.first_kf_id;
  r.first_frame_id = mp.first_frame_id;
  r.visible = mp.visible;
  r.found = mp.found;
  r.dynamic = mp.dynamic;
  return r;
}

Payload payloadOf(const Map& map, const MapFileContext& ctx) {
  Payload p;
  p.camera = cameraRecord(ctx);
  p.vocabulary = ctx.vocabulary ? vocabularyChecksum(*ctx.vocabulary) : 0;
  p.next_kf_id = map.nextKeyFrameId();
  p.next_point_id = map.nextPointId();
  for (const auto& kf : map.keyframes()) p.keyframes.push_back(keyFrameRecord(*kf));
  for (const auto& mp : map.mapPoints()) p.points.push_back(mapPointRecord(*mp));
  return p;
}

template <class T>
std::string serialized(const T& value) {
  std::ostringstream os(std::ios::binary);
  {
    cereal::PortableBinaryOutputArchive ar(os);
    ar(value);
  }
  return os.str();
}

// ---- reading and checking ----

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error(path + ": map file not found or not readable; check the path (maps are written by "
                       "yolo_slam_run --save-map)");
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

size_t headerSize() { return serialized(Header{}).size(); }

Header readHeader(const std::string& path, const std::string& bytes) {
  Header h;
  if (bytes.size() < headerSize())
    throw Error(path + ": map file truncated (" + std::to_string(bytes.size()) + " bytes, shorter than its header); " +
                kRebuildHint);
  std::istringstream is(bytes.substr(0, headerSize()), std::ios::binary);
  try {
    cereal::PortableBinaryInputArchive ar(is);
    ar(h);
  } catch (const cereal::Exception& e) {
    throw Error(path + ": not a yolo_slam map file (unreadable header: " + e.what() + "); " + kRebuildHint);
  }
  if (h.magic != kMagic) throw Error(path + ": not a yolo_slam map file (wrong magic); " + kRebuildHint);
  return h;
}

void checkHeader(const std::string& path, const Header& h, size_t payload_bytes) {
  if (h.version != kMapFileFormatVersion)
    throw Error(path + ": map file format version " + std::to_string(h.version) + ", this build reads version " +
                std::to_string(kMapFileFormatVersion) + "; " + kRebuildHint + " of this build");
  if (payload_bytes < h.payload_size)
    throw Error(path + ": map file truncated (payload " + std::to_string(payload_bytes) + " of " +
                std::to_string(h.payload_size) + " bytes); the write was interrupted or the copy is incomplete; " +
                kRebuildHint);
  if (payload_bytes > h.payload_size)
    throw Error(path + ": map file corrupted (" + std::to_string(payload_bytes - h.payload_size) +
                " bytes after the payload); " + kRebuildHint);
}

Payload parsePayload(const std::string& path, const std::string& bytes, size_t offset, const Header& h) {
  const uint64_t sum = fnv1a(reinterpret_cast<const uint8_t*>(bytes.data()) + offset, h.payload_size);
  if (sum != h.payload_checksum)
    throw Error(path + ": map file corrupted (payload checksum mismatch); " + kRebuildHint);
  Payload p;
  std::istringstream is(bytes.substr(offset), std::ios::binary);
  t_payload_bytes = h.payload_size;
  try {
    cereal::PortableBinaryInputArchive ar(is);
    ar(p);
  } catch (const cereal::Exception& e) {
    throw Error(path + ": map file corrupted (unreadable payload: " + e.what() + "); " + kRebuildHint);
  }
  return p;
}

bool near(double a, double b) { return std::abs(a - b) <= kCameraTolerance * std::max(1.0, std::abs(a)); }

template <size_t N>
bool near(const std::array<double, N>& a, const std::array<double, N>& b) {
  for (size_t i = 0; i < N; ++i)
    if (!near(a[i], b[i])) return false;
  return true;
}

// "fx fy cx cy, k1 k2 p1 p2 k3, WxH, bf" for the camera error.
std::string describe(const CameraRecord& c) {
  std::ostringstream os;
  os.precision(10);
  for (double v : c.intrinsics) os << v << ' ';
  os << "distortion";
  for (double v : c.distortion) os << ' ' << v;
  os << ", " << c.width << 'x' << c.height << ", bf " << c.bf;
  return os.str();
}

void checkIdentity(const std::string& path, const Payload& p, const MapFileContext& ctx) {
  const uint64_t voc = ctx.vocabulary ? vocabularyChecksum(*ctx.vocabulary) : 0;
  if (p.vocabulary != voc) {
    if (p.vocabulary == 0)
      throw Error(path + ": map was built without a vocabulary; load it with --no-vocabulary or rebuild it");
    throw Error(path + ": map was built with another vocabulary" +
                (voc ? std::string() : std::string(" (this run has none)")) +
                "; load it with the vocabulary it was built with (--vocabulary FILE) or rebuild it");
  }
  const CameraRecord now = cameraRecord(ctx);
  const CameraRecord& c = p.camera;
  if (!near(c.intrinsics, now.intrinsics) || !near(c.distortion, now.distortion) || c.width != now.width ||
      c.height != now.height || !near(c.bf, now.bf))
    throw Error(path + ": map was built with another camera (Camera.* of the map: " + describe(c) + "; of this run: " +
                describe(now) + "); use the settings file it was built with (--config) or rebuild the map");
  if (c.orb_levels != now.orb_levels || !near(c.orb_scale_factor, now.orb_scale_factor))
    throw Error(path + ": map was built with ORBextractor.nLevels " + std::to_string(c.orb_levels) +
                ", scaleFactor " + std::to_string(c.orb_scale_factor) +
                "; use those settings (--set) or rebuild the map");
}

// ---- rebuilding the map objects ----

[[noreturn]] void corrupt(const std::string& path, const std::string& what) {
  throw Error(path + ": map file corrupted (" + what + "); " + kRebuildHint);
}

bool finitePose(const PoseRecord& T) {
  return std::all_of(T.begin(), T.end(), [](double v) { return std::isfinite(v); });
}

// Values the frame rebuild indexes or divides by: a pyramid level that exists, finite
// coordinates, depths and poses.
void checkKeyFrameValues(const std::string& path, const KeyFrameRecord& r, int levels) {
  const std::string kf = "keyframe " + std::to_string(r.id);
  if (!finitePose(r.T_cw) || !finitePose(r.T_cp)) corrupt(path, kf + " has a non-finite pose");
  for (const KeyPointRecord& k : r.keypoints)
    if (k.octave < 0 || k.octave >= levels || !std::isfinite(k.x) || !std::isfinite(k.y) || !std::isfinite(k.size) ||
        !std::isfinite(k.angle))
      corrupt(path, kf + " has a keypoint off the image pyramid");
  for (size_t i = 0; i < r.depth.size(); ++i)
    if (!std::isfinite(r.depth[i]) || !std::isfinite(r.right_u[i])) corrupt(path, kf + " has a non-finite depth");
}

KeyFramePtr makeKeyFrame(const std::string& path, const KeyFrameRecord& r, const CameraModel& cam,
                         const FrameGeometry& geom, const std::shared_ptr<const ScalePyramid>& pyr) {
  const size_t n = r.keypoints.size();
  if (r.descriptors.size() != n * kDescriptorBytes || r.depth.size() != n || r.right_u.size() != n ||
      r.dynamic.size() != n || (!r.motion.empty() && r.motion.size() != n))
    corrupt(path, "keyframe " + std::to_string(r.id) + " has inconsistent keypoint arrays");
  checkKeyFrameValues(path, r, pyr->n_levels);
  features::FeatureFrame ff;
  ff.stamp = r.stamp;
  for (const KeyPointRecord& k : r.keypoints)
    ff.keypoints.emplace_back(k.x, k.y, k.size, k.angle, k.response, k.octave, k.class_id);
  ff.keypoints_un = ff.keypoints;
  ff.descriptors = cv::Mat(static_cast<int>(n), static_cast<int>(kDescriptorBytes), CV_8U);
  if (n > 0) std::copy(r.descriptors.begin(), r.descriptors.end(), ff.descriptors.data);
  ff.depth = r.depth;
  ff.right_u = r.right_u;
  ff.dynamic = r.dynamic;
  ff.motion = r.motion;
  Frame F(ff, cam, geom, pyr, r.frame_id);
  F.setPose(fromRecord(r.T_cw));
  auto kf = std::make_shared<KeyFrame>(r.id, F);
  kf->T_cp = fromRecord(r.T_cp);
  kf->first_connection = r.first_connection;
  kf->not_erase = r.not_erase;
  return kf;
}

using KeyFrameIndex = std::unordered_map<long, KeyFramePtr>;

KeyFramePtr lookUp(const std::string& path, const KeyFrameIndex& index, int64_t id, const char* what) {
  auto it = index.find(static_cast<long>(id));
  if (it == index.end()) corrupt(path, std::string(what) + " refers to unknown keyframe " + std::to_string(id));
  return it->second;
}

// Covisibility, spanning tree (children from the parents) and loop edges.
void linkKeyFrames(const std::string& path, const Payload& p, const KeyFrameIndex& index) {
  for (const KeyFrameRecord& r : p.keyframes) {
    const KeyFramePtr& kf = index.at(static_cast<long>(r.id));
    for (const auto& c : r.connections) kf->connections[lookUp(path, index, c.first, "a connection")] = c.second;
    kf->updateBestCovisibles();
    if (r.parent != kNone) {
      kf->parent = lookUp(path, index, r.parent, "a parent link");
      kf->parent->children.insert(kf.get());
    }
    for (int64_t l : r.loop_edges) kf->loop_edges.insert(lookUp(path, index, l, "a loop edge"));
  }
}

MapPointPtr makeMapPoint(const std::string& path, const MapPointRecord& r, const KeyFrameIndex& index) {
  const Eigen::Vector3d Xw(r.Xw[0], r.Xw[1], r.Xw[2]);
  if (!Xw.allFinite() || !std::isfinite(r.normal[0] + r.normal[1] + r.normal[2]) || !std::isfinite(r.min_dist) ||
      !std::isfinite(r.max_dist))
    corrupt(path, "point " + std::to_string(r.id) + " has a non-finite position or scale range");
  auto mp = std::make_shared<MapPoint>(r.id, Xw, nullptr, r.first_frame_id);
  mp->normal = Eigen::Vector3d(r.normal[0], r.normal[1], r.normal[2]);
  mp->min_dist = r.min_dist;
  mp->max_dist = r.max_dist;
  if (r.descriptor.size() == kDescriptorBytes) {
    mp->descriptor = cv::Mat(1, static_cast<int>(kDescriptorBytes), CV_8U);
    std::copy(r.descriptor.begin(), r.descriptor.end(), mp->descriptor.data);
  }
  for (const auto& o : r.observations) {
    const KeyFramePtr kf = lookUp(path, index, o.first, "an observation");
    if (o.second >= static_cast<uint32_t>(kf->f.N))
      corrupt(path, "point " + std::to_string(r.id) + " observes a keypoint keyframe " + std::to_string(o.first) +
                        " does not have");
    Map::addObservation(mp, kf, o.second);
  }
  mp->ref_kf = r.ref_kf == kNone ? nullptr : lookUp(path, index, r.ref_kf, "a reference keyframe").get();
  mp->first_kf_id = r.first_kf_id;
  mp->visible = r.visible;
  mp->found = r.found;
  mp->dynamic = r.dynamic;
  return mp;
}

void buildMap(const std::string& path, const Payload& p, const MapFileContext& ctx, Map& out) {
  auto pyr = std::make_shared<const ScalePyramid>(ScalePyramid::make(ctx.orb_levels, ctx.orb_scale_factor));
  const FrameGeometry geom = FrameGeometry::make(ctx.camera);
  KeyFrameIndex index;
  std::vector<KeyFramePtr> ordered;  // the origin first: Map::addKeyFrame makes the first one the origin
  for (const KeyFrameRecord& r : p.keyframes) {
    KeyFramePtr kf = makeKeyFrame(path, r, ctx.camera, geom, pyr);
    computeBow(ctx.vocabulary, kf->f);
    if (!index.emplace(kf->id, kf).second) corrupt(path, "keyframe " + std::to_string(r.id) + " twice");
    ordered.insert(r.is_origin ? ordered.begin() : ordered.end(), kf);
  }
  for (const KeyFramePtr& kf : ordered) out.addKeyFrame(kf);
  linkKeyFrames(path, p, index);
  for (const MapPointRecord& r : p.points) out.addMapPoint(makeMapPoint(path, r, index));
  out.restoreIdCounters(static_cast<long>(p.next_kf_id), static_cast<long>(p.next_point_id));
}

}  // namespace

uint64_t vocabularyChecksum(const vocabulary::Vocabulary& voc) {
  uint64_t h = kFnvBasis;
  h = fnv1aValue(static_cast<int32_t>(voc.branching()), h);
  h = fnv1aValue(static_cast<int32_t>(voc.levels()), h);
  h = fnv1aValue(static_cast<int32_t>(voc.weighting()), h);
  for (vocabulary::NodeId n = 0; n < voc.nodeCount(); ++n) {
    h = fnv1aValue(voc.parent(n), h);
    h = fnv1a(voc.nodeDescriptor(n), kDescriptorBytes, h);
  }
  for (vocabulary::WordId w = 0; w < voc.size(); ++w) {
    h = fnv1aValue(voc.wordNode(w), h);
    h = fnv1aValue(voc.wordWeight(w), h);
  }
  return h == 0 ? 1 : h;  // 0 stands for "no vocabulary"
}

MapFileInfo saveMapFile(const std::string& path, const Map& map, const MapFileContext& context) {
  Stopwatch sw;
  const std::string payload = serialized(payloadOf(map, context));
  Header h;
  h.payload_size = payload.size();
  h.payload_checksum = fnv1a(reinterpret_cast<const uint8_t*>(payload.data()), payload.size());
  const std::string bytes = serialized(h) + payload;
  io::writeFileAtomic(path, bytes);
  MapFileInfo info;
  info.bytes = bytes.size();
  info.keyframes = map.numKeyFrames();
  info.map_points = map.numMapPoints();
  info.ms = sw.ms();
  return info;
}

MapFileInfo loadMapFile(const std::string& path, const MapFileContext& context, Map& out) {
  Stopwatch sw;
  if (out.numKeyFrames() > 0 || out.numMapPoints() > 0)
    throw Error(path + ": loadMapFile needs an empty map (load into a new Map)");
  const std::string bytes = readWholeFile(path);
  const Header h = readHeader(path, bytes);
  const size_t offset = headerSize();
  checkHeader(path, h, bytes.size() - offset);
  const Payload p = parsePayload(path, bytes, offset, h);
  checkIdentity(path, p, context);
  buildMap(path, p, context, out);
  MapFileInfo info;
  info.bytes = bytes.size();
  info.keyframes = out.numKeyFrames();
  info.map_points = out.numMapPoints();
  info.ms = sw.ms();
  return info;
}

}  // namespace slam
}  // namespace yolo_slam
