#include "yolo_slam/mapping/dense_map.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/io/atomic_file.h"

#include <octomap/OcTree.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace yolo_slam {
namespace mapping {

namespace {

const OptionTable<DenseMapOptions>& denseFields() {
  using O = DenseMapOptions;
  static const OptionTable<O> table = {
      {"DenseMap.enabled", &O::enabled},
      {"DenseMap.resolution", &O::resolution_m, Range::positive()},
      {"DenseMap.maxRange", &O::max_range_m, Range::positive()},
      {"DenseMap.pixelStride", &O::pixel_stride, Range::atLeast(1)},
      {"DenseMap.cloudResolution", &O::cloud_resolution_m, Range::positive()},
      {"DenseMap.probHit", &O::prob_hit, Range::open(0.5, 1)},
      {"DenseMap.probMiss", &O::prob_miss, Range::open(0, 0.5)},
      {"DenseMap.queueSize", &O::queue_size, Range::atLeast(1)},
      {"DenseMap.threadNice", &O::thread_nice, Range::closed(0, 19)},
      {"DenseMap.finalRebuild", &O::final_rebuild},
      {"DenseMap.maskPeople", &O::mask_people},
  };
  return table;
}

const OptionTable<StaticMaskOptions>& maskFields() {
  using O = StaticMaskOptions;
  static const OptionTable<O> table = {
      {"DenseMap.maskMargin", &O::margin_px, Range::atLeast(0)},
      {"DenseMap.maskSampleStride", &O::sample_stride_px, Range::atLeast(1)},
  };
  return table;
}

// Cloud voxel indices are packed 21 bits per axis (+- 2^20 voxels: kilometres at 2 cm).
constexpr int kKeyBits = 21;
constexpr int64_t kKeyOffset = int64_t(1) << (kKeyBits - 1);
constexpr uint64_t kKeyMask = (uint64_t(1) << kKeyBits) - 1;
// OctoMap's tree depth: a leaf at depth d has edge resolution * 2^(kTreeDepth - d).
constexpr unsigned kTreeDepth = 16;
// Rough per-entry overhead of an unordered_map node beyond key and value (next pointer, hash).
constexpr size_t kHashNodeOverhead = 16;
constexpr uint8_t kGrey = 128;
// Scans integrated lazily before the inner nodes are updated and the tree pruned.
constexpr int kInnerUpdateInterval = 10;

std::array<uint8_t, 3> pixelRgb(const cv::Mat& image, int u, int v, bool rgb_order) {
  if (image.empty()) return {kGrey, kGrey, kGrey};
  if (image.type() == CV_8UC1) {
    const uint8_t g = image.at<uint8_t>(v, u);
    return {g, g, g};
  }
  const cv::Vec3b c = image.at<cv::Vec3b>(v, u);
  return rgb_order ? std::array<uint8_t, 3>{c[0], c[1], c[2]} : std::array<uint8_t, 3>{c[2], c[1], c[0]};
}

void checkInputs(const cv::Mat& image, const cv::Mat& depth_m, const cv::Mat& mask) {
  if (depth_m.type() != CV_32FC1) throw Error("dense map: depth must be CV_32FC1 metres");
  if (mask.type() != CV_8UC1 || mask.size() != depth_m.size())
    throw Error("dense map: the static mask must be CV_8UC1 of the depth image's size");
  if (!image.empty() && (image.size() != depth_m.size() || (image.type() != CV_8UC3 && image.type() != CV_8UC1)))
    throw Error("dense map: the colour image must be CV_8UC3 or CV_8UC1 of the depth image's size");
}

}  // namespace

void DenseMapOptions::validate(const std::string& where) const {
  checkOptions(*this, where, denseFields());
  checkOptions(mask, where, maskFields());
}

DenseMapOptions DenseMapOptions::load(const Config& cfg) {
  DenseMapOptions o;
  readOptions(cfg, o, denseFields());
  readOptions(cfg, o.mask, maskFields());
  return o;
}

size_t KeyFrameCloud::bytes() const {
  return points.capacity() * sizeof(points[0]) + rgb.capacity() * sizeof(rgb[0]) +
         beyond.capacity() * sizeof(beyond[0]);
}

KeyFrameCloud backProject(const CameraModel& cam, const DenseMapOptions& o, const cv::Mat& image,
                          const cv::Mat& depth_m, const cv::Mat& static_mask) {
  checkInputs(image, depth_m, static_mask);
  std::vector<cv::Point2f> px;
  std::vector<float> depth;
  const int s = o.pixel_stride;
  for (int v = s / 2; v < depth_m.rows; v += s) {
    const float* d = depth_m.ptr<float>(v);
    const uint8_t* m = static_mask.ptr<uint8_t>(v);
    for (int u = s / 2; u < depth_m.cols; u += s) {
      if (!(d[u] > 0) || !std::isfinite(d[u]) || m[u] == 0) continue;
      px.emplace_back(static_cast<float>(u), static_cast<float>(v));
      depth.push_back(d[u]);
    }
  }
  const std::vector<cv::Point2f> und = cam.hasDistortion() ? cam.undistort(px) : px;
  KeyFrameCloud c;
  c.points.reserve(px.size());
  c.rgb.reserve(px.size());
  for (size_t i = 0; i < px.size(); ++i) {
    const Eigen::Vector3f p = cam.unproject(und[i].x, und[i].y, depth[i]).cast<float>();
    // Range along the ray, not depth: OctoMap's maxrange is a ray length.
    if (p.norm() > o.max_range_m) {
      c.beyond.push_back(p);
      continue;
    }
    c.points.push_back(p);
    c.rgb.push_back(pixelRgb(image, static_cast<int>(px[i].x), static_cast<int>(px[i].y), cam.rgb_order));
  }
  return c;
}

DenseMap::DenseMap(const CameraModel& cam, const DenseMapOptions& options) : cam_(cam), opt_(options) {
  opt_.validate("DenseMap");
  clear();
}

DenseMap::~DenseMap() = default;
DenseMap::DenseMap(DenseMap&&) noexcept = default;
DenseMap& DenseMap::operator=(DenseMap&&) noexcept = default;

void DenseMap::clear() {
  tree_ = std::make_unique<octomap::OcTree>(opt_.resolution_m);
  tree_->setProbHit(opt_.prob_hit);
  tree_->setProbMiss(opt_.prob_miss);
  cells_.clear();
  inner_stale_ = false;
  scans_since_inner_ = 0;
}

uint64_t DenseMap::cloudKey(const Eigen::Vector3f& p) const {
  uint64_t key = 0;
  for (int a = 0; a < 3; ++a) {
    const int64_t i = static_cast<int64_t>(std::floor(p[a] / opt_.cloud_resolution_m)) + kKeyOffset;
    key = (key << kKeyBits) | (static_cast<uint64_t>(i) & kKeyMask);
  }
  return key;
}

void DenseMap::integrate(const KeyFrameCloud& cloud, const Pose& T_wc) {
  const Eigen::Matrix3f R = T_wc.linear().cast<float>();
  const Eigen::Vector3f t = T_wc.translation().cast<float>();
  octomap::Pointcloud scan;
  scan.reserve(cloud.points.size() + cloud.beyond.size());
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    const Eigen::Vector3f w = R * cloud.points[i] + t;
    scan.push_back(w.x(), w.y(), w.z());
    CloudCell& c = cells_[cloudKey(w)];
    c.sum += w;
    for (int k = 0; k < 3; ++k) c.rgb[k] += cloud.rgb[i][k];
    ++c.n;
  }
  for (const Eigen::Vector3f& p : cloud.beyond) {
    const Eigen::Vector3f w = R * p + t;
    scan.push_back(w.x(), w.y(), w.z());
  }
  // discretize: one ray per end voxel, the same map for a fraction of the ray casting; lazy:
  // inner nodes are updated once for many scans (half the cost of a scan).
  tree_->insertPointCloud(scan, octomap::point3d(t.x(), t.y(), t.z()), opt_.max_range_m, true, true);
  if (++scans_since_inner_ >= kInnerUpdateInterval) syncInner();
  else inner_stale_ = true;
}

void DenseMap::syncInner() const {
  if (!inner_stale_ && scans_since_inner_ == 0) return;
  tree_->updateInnerOccupancy();
  tree_->prune();
  inner_stale_ = false;
  scans_since_inner_ = 0;
}

namespace {
std::vector<Voxel> leavesOf(const octomap::OcTree& tree, bool occupied) {
  std::vector<Voxel> out;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (tree.isNodeOccupied(*it) != occupied) continue;
    const octomap::point3d c = it.getCoordinate();
    out.push_back({Eigen::Vector3d(c.x(), c.y(), c.z()), it.getSize()});
  }
  return out;
}
}  // namespace

std::vector<Voxel> DenseMap::occupiedLeaves() const {
  syncInner();
  return leavesOf(*tree_, true);
}

std::vector<Voxel> DenseMap::freeLeaves() const {
  syncInner();
  return leavesOf(*tree_, false);
}

OccupancyGrid2D projectToGrid(const std::vector<Voxel>& occupied, const std::vector<Voxel>& free,
                              double z_min, double z_max, double resolution) {
  OccupancyGrid2D g;
  g.resolution = resolution;
  auto inBand = [&](const Voxel& v) { return v.centre.z() >= z_min && v.centre.z() <= z_max; };
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(Range::kInf), hi = -lo;
  for (const auto* set : {&occupied, &free})
    for (const Voxel& v : *set) {
      if (!inBand(v)) continue;
      lo = lo.cwiseMin(v.centre.head<2>() - Eigen::Vector2d::Constant(v.size / 2));
      hi = hi.cwiseMax(v.centre.head<2>() + Eigen::Vector2d::Constant(v.size / 2));
    }
  if (!(lo.x() <= hi.x())) return g;
  g.origin_x = lo.x();
  g.origin_y = lo.y();
  g.width = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / resolution)));
  g.height = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / resolution)));
  g.cells.assign(static_cast<size_t>(g.width) * g.height, OccupancyGrid2D::kUnknown);
  // Free first, occupied over it: one occupied leaf in the band blocks the cell.
  auto paint = [&](const std::vector<Voxel>& set, int8_t value) {
    for (const Voxel& v : set) {
      if (!inBand(v)) continue;
      const int x0 = static_cast<int>(std::floor((v.centre.x() - v.size / 2 - g.origin_x) / resolution + 1e-9));
      const int y0 = static_cast<int>(std::floor((v.centre.y() - v.size / 2 - g.origin_y) / resolution + 1e-9));
      const int n = std::max(1, static_cast<int>(std::lround(v.size / resolution)));
      for (int y = std::max(0, y0); y < std::min(g.height, y0 + n); ++y)
        for (int x = std::max(0, x0); x < std::min(g.width, x0 + n); ++x) {
          int8_t& c = g.cells[static_cast<size_t>(y) * g.width + x];
          if (c != OccupancyGrid2D::kOccupied) c = value;
        }
    }
  };
  paint(free, OccupancyGrid2D::kFree);
  paint(occupied, OccupancyGrid2D::kOccupied);
  return g;
}

size_t DenseMap::occupiedVoxels() const {
  syncInner();
  size_t n = 0;
  for (auto it = tree_->begin_leafs(), end = tree_->end_leafs(); it != end; ++it)
    if (tree_->isNodeOccupied(*it)) n += size_t(1) << (3 * (kTreeDepth - it.getDepth()));
  return n;
}

namespace {
// Centres of the finest voxels inside an occupied leaf.
void expandLeaf(const Eigen::Vector3d& centre, double size, double res, std::vector<Eigen::Vector3d>& out) {
  const int n = std::max(1, static_cast<int>(std::lround(size / res)));
  const Eigen::Vector3d corner = centre - Eigen::Vector3d::Constant(size / 2);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) out.push_back(corner + res * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));
}

std::vector<Eigen::Vector3d> occupiedCentresOf(const octomap::OcTree& tree) {
  std::vector<Eigen::Vector3d> out;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const octomap::point3d c = it.getCoordinate();
    expandLeaf(Eigen::Vector3d(c.x(), c.y(), c.z()), it.getSize(), tree.getResolution(), out);
  }
  return out;
}
}  // namespace

std::vector<Eigen::Vector3d> DenseMap::occupiedCentres() const {
  syncInner();
  return occupiedCentresOf(*tree_);
}

std::vector<ColouredPoint> DenseMap::cloud() const {
  syncInner();
  std::vector<ColouredPoint> out;
  out.reserve(cells_.size());
  for (const auto& kv : cells_) {
    const CloudCell& c = kv.second;
    const Eigen::Vector3f p = c.sum / static_cast<float>(c.n);
    const octomap::OcTreeNode* node = tree_->search(p.x(), p.y(), p.z());
    if (!node || !tree_->isNodeOccupied(node)) continue;
    ColouredPoint cp;
    cp.p = p;
    for (int k = 0; k < 3; ++k) cp.rgb[k] = static_cast<uint8_t>(c.rgb[k] / c.n);
    out.push_back(cp);
  }
  return out;
}

size_t DenseMap::memoryBytes() const {
  syncInner();
  const size_t cell = sizeof(uint64_t) + sizeof(CloudCell) + kHashNodeOverhead;
  return tree_->memoryUsage() + cells_.size() * cell + cells_.bucket_count() * sizeof(void*);
}

void DenseMap::writeOctomap(const std::string& path) const {
  syncInner();
  std::ostringstream os;
  if (!tree_->writeBinaryConst(os)) throw Error(path + ": octomap could not serialise the tree");
  io::writeFileAtomic(path, os.str());
}

std::vector<Eigen::Vector3d> readOctomapOccupied(const std::string& path, double* resolution) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the octomap file; check the path");
  octomap::OcTree tree(DenseMapOptions::kDefaultResolutionM);
  if (!tree.readBinary(in))
    throw Error(path + ": not an OctoMap binary tree (.bt); write it with yolo_slam_run --octomap");
  if (resolution) *resolution = tree.getResolution();
  return occupiedCentresOf(tree);
}

// ---- PLY --------------------------------------------------------------------------------

namespace {
constexpr const char* kPlyVertexProps[] = {"float x", "float y", "float z",
                                           "uchar red", "uchar green", "uchar blue"};
constexpr size_t kPlyVertexBytes = 3 * sizeof(float) + 3;
}  // namespace

void writePly(const std::string& path, const std::vector<ColouredPoint>& points) {
  std::ostringstream os;
  os << "ply\nformat binary_little_endian 1.0\ncomment yolo_slam dense static map\nelement vertex "
     << points.size() << "\n";
  for (const char* p : kPlyVertexProps) os << "property " << p << "\n";
  os << "end_header\n";
  std::string body(points.size() * kPlyVertexBytes, '\0');
  char* w = &body[0];
  for (const ColouredPoint& p : points) {
    // x86 and ARM hosts are little-endian: the floats are written as they lie in memory.
    std::memcpy(w, p.p.data(), 3 * sizeof(float));
    std::memcpy(w + 3 * sizeof(float), p.rgb.data(), 3);
    w += kPlyVertexBytes;
  }
  io::writeFileAtomic(path, os.str() + body);
}

namespace {
struct PlyHeader {
  bool binary = false;
  size_t vertices = 0;
};

PlyHeader readPlyHeader(std::istream& in, const std::string& path) {
  const std::string fix = "; expected a PLY as yolo_slam_run --cloud writes";
  std::string line;
  if (!std::getline(in, line) || line != "ply") throw Error(path + ": not a PLY file (no 'ply' line)" + fix);
  PlyHeader h;
  std::vector<std::string> props;
  bool format = false;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string f;
      ls >> f;
      if (f != "binary_little_endian" && f != "ascii") throw Error(path + ": PLY format '" + f + "' not supported" + fix);
      h.binary = f == "binary_little_endian";
      format = true;
    } else if (word == "element") {
      std::string name;
      ls >> name >> h.vertices;
      if (name != "vertex") throw Error(path + ": PLY element '" + name + "' not supported" + fix);
    } else if (word == "property") {
      props.push_back(line.substr(9));
    }
  }
  if (line != "end_header" || !format) throw Error(path + ": PLY header incomplete" + fix);
  if (props != std::vector<std::string>(std::begin(kPlyVertexProps), std::end(kPlyVertexProps)))
    throw Error(path + ": PLY vertex properties are not 'x y z' float and 'red green blue' uchar" + fix);
  return h;
}
}  // namespace

std::vector<ColouredPoint> readPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the PLY file; check the path");
  const PlyHeader h = readPlyHeader(in, path);
  std::vector<ColouredPoint> out(h.vertices);
  for (size_t i = 0; i < h.vertices; ++i) {
    ColouredPoint& p = out[i];
    if (h.binary) {
      char buf[kPlyVertexBytes];
      in.read(buf, kPlyVertexBytes);
      std::memcpy(p.p.data(), buf, 3 * sizeof(float));
      std::memcpy(p.rgb.data(), buf + 3 * sizeof(float), 3);
    } else {
      int c[3] = {0, 0, 0};
      in >> p.p.x() >> p.p.y() >> p.p.z() >> c[0] >> c[1] >> c[2];
      for (int k = 0; k < 3; ++k) p.rgb[k] = static_cast<uint8_t>(c[k]);
    }
    if (!in) throw Error(path + ": PLY ends after " + std::to_string(i) + " of " + std::to_string(h.vertices) + " vertices");
  }
  return out;
}

}  // namespace mapping
}  // namespace yolo_slam
