// Scores the dense static map on a synthetic sequence (yolo_slam_synth: masks/ and boxes.txt).
//
//   dense_map_bench mask  --sequence DIR [--config YAML] [--set K=V ...] [--step N]
//       The static mask of every N-th frame (ground-truth person boxes, the screening options of
//       the settings) against masks/: person pixels (with depth) left in the static set, and
//       static pixels (with depth) removed.
//   dense_map_bench score --sequence DIR --trajectory CameraTrajectory.txt --octomap MAP.bt
//                         [--config YAML] [--step N]
//       The map's occupied voxels against the scene's geometry: every N-th tracked frame's depth,
//       split by masks/ into static and person pixels (DenseMap.pixelStride, maxRange), is
//       placed with the run's own pose (so pose error is not counted as map error). Reports the
//       share of occupied voxels on people (a person voxel not within one voxel of a static
//       one), the share not within one voxel of any static surface, and the share of static
//       voxels within two voxels of an occupied one (coverage).
// Both print one JSON object. docs/dense-map.md.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/json.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/io/depth.h"
#include "yolo_slam/io/text_table.h"
#include "yolo_slam/io/trajectory.h"
#include "yolo_slam/io/tum_sequence.h"
#include "yolo_slam/mapping/dense_map.h"
#include "yolo_slam/mapping/static_mask.h"
#include "yolo_slam/screening/screener.h"

#include "gt_boxes.h"

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <unordered_set>
#include <vector>

using namespace yolo_slam;
using bench::kStampMatchS;
using bench::readPersonBoxes;
using bench::stampKey;

namespace {

const char* const kUsage =
    "usage: dense_map_bench mask --sequence DIR [--config YAML] [--set K=V ...] [--step N]\n"
    "       dense_map_bench score --sequence DIR --trajectory TRAJ --octomap MAP.bt [--config YAML]\n"
    "                             [--set K=V ...] [--step N]\n";
constexpr uint8_t kMaskDynamic = 128;  // masks/: > 127 dynamic, 255 a person
constexpr int kCoverageRadiusVoxels = 2;
constexpr int kStaticToleranceVoxels = 1;

struct Args {
  std::string command, sequence, config, trajectory, octomap;
  std::vector<std::string> overrides;
  int step = 10;
};

Args parseArgs(int argc, char** argv) {
  if (argc < 2) throw Error(std::string("missing command\n") + kUsage);
  Args a;
  a.command = argv[1];
  for (int i = 2; i < argc; ++i) {
    const std::string s = argv[i];
    auto need = [&]() -> std::string {
      if (i + 1 >= argc) throw Error("missing value after " + s);
      return argv[++i];
    };
    if (s == "--sequence") a.sequence = need();
    else if (s == "--config") a.config = need();
    else if (s == "--trajectory") a.trajectory = need();
    else if (s == "--octomap") a.octomap = need();
    else if (s == "--set") a.overrides.push_back(need());
    else if (s == "--step") a.step = std::max(1, std::stoi(need()));
    else throw Error("unknown option '" + s + "'\n" + kUsage);
  }
  if (a.sequence.empty()) throw Error(std::string("--sequence is required\n") + kUsage);
  if (a.config.empty()) a.config = joinPath(a.sequence, "camera.yaml");
  return a;
}

Config loadConfig(const Args& a) {
  Config cfg = Config::fromFile(a.config);
  for (const auto& o : a.overrides) cfg.setFromAssignment(o);
  return cfg;
}

cv::Mat loadGtMask(const io::TumSequence& seq, size_t i) {
  const std::string rgb = seq.frames()[i].rgb_path;
  const std::string name = rgb.substr(rgb.find_last_of('/') + 1);
  const std::string path = joinPath(seq.dir(), "masks/" + name);
  cv::Mat m = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (m.empty()) throw Error(path + ": no ground-truth mask; generate the sequence with yolo_slam_synth");
  return m;
}

Json runMask(const Args& a) {
  const Config cfg = loadConfig(a);
  const CameraModel cam = CameraModel::load(cfg);
  const screening::Screener screener(screening::ScreeningOptions::load(cfg));
  const mapping::DenseMapOptions dense = mapping::DenseMapOptions::load(cfg);
  const io::TumSequence seq = io::TumSequence::open(a.sequence);
  const auto boxes = readPersonBoxes(joinPath(a.sequence, "boxes.txt"));
  long person = 0, person_static = 0, stat = 0, stat_removed = 0, frames = 0;
  for (size_t i = 0; i < seq.size(); i += a.step) {
    const cv::Mat depth = seq.loadDepth(i, cam.depth_map_factor);
    const cv::Mat gt = loadGtMask(seq, i);
    const auto it = boxes.find(stampKey(seq.frames()[i].rgb_stamp));
    const cv::Mat mask = mapping::staticMask(depth, it == boxes.end() ? detection::Boxes{} : it->second, screener, dense.mask);
    ++frames;
    for (int v = 0; v < depth.rows; ++v)
      for (int u = 0; u < depth.cols; ++u) {
        if (!(depth.at<float>(v, u) > 0)) continue;  // no depth: never integrated either way
        const bool kept = mask.at<uint8_t>(v, u) != 0;
        const uint8_t g = gt.at<uint8_t>(v, u);
        if (g == 255) ++person, person_static += kept;
        else if (g < kMaskDynamic) ++stat, stat_removed += !kept;
      }
  }
  return Json{{"frames", frames},
              {"mode", screening::toString(screener.options().mode)},
              {"mask_margin_px", dense.mask.margin_px},
              {"person_pixels", person},
              {"person_left_static", person_static},
              {"person_left_static_share", jsonRatio(person_static, person)},
              {"static_pixels", stat},
              {"static_removed", stat_removed},
              {"static_removed_share", jsonRatio(stat_removed, stat)}};
}

// ---- score -------------------------------------------------------------------------------

using VoxelSet = std::unordered_set<uint64_t>;
constexpr int kKeyBits = 21;
constexpr int64_t kKeyOffset = int64_t(1) << (kKeyBits - 1);

uint64_t pack(int64_t x, int64_t y, int64_t z) {
  const uint64_t m = (uint64_t(1) << kKeyBits) - 1;
  return ((uint64_t(x + kKeyOffset) & m) << (2 * kKeyBits)) | ((uint64_t(y + kKeyOffset) & m) << kKeyBits) |
         (uint64_t(z + kKeyOffset) & m);
}

uint64_t voxelOf(const Eigen::Vector3d& p, double res) {
  return pack(static_cast<int64_t>(std::floor(p.x() / res)), static_cast<int64_t>(std::floor(p.y() / res)),
              static_cast<int64_t>(std::floor(p.z() / res)));
}

// Whether a voxel of `set` lies within `radius` voxels (Euclidean) of p's voxel.
bool near(const VoxelSet& set, const Eigen::Vector3d& p, double res, int radius) {
  const int64_t x = static_cast<int64_t>(std::floor(p.x() / res)), y = static_cast<int64_t>(std::floor(p.y() / res)),
                z = static_cast<int64_t>(std::floor(p.z() / res));
  for (int dx = -radius; dx <= radius; ++dx)
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dz = -radius; dz <= radius; ++dz)
        if (dx * dx + dy * dy + dz * dz <= radius * radius && set.count(pack(x + dx, y + dy, z + dz))) return true;
  return false;
}

Eigen::Vector3d centreOf(uint64_t key, double res) {
  const uint64_t m = (uint64_t(1) << kKeyBits) - 1;
  const auto axis = [&](int shift) { return (static_cast<int64_t>((key >> shift) & m) - kKeyOffset + 0.5) * res; };
  return {axis(2 * kKeyBits), axis(kKeyBits), axis(0)};
}

const StampedPose* poseAt(const Trajectory& traj, double stamp) {
  for (const StampedPose& p : traj)
    if (std::abs(p.stamp - stamp) < kStampMatchS) return &p;
  return nullptr;
}

Json runScore(const Args& a) {
  if (a.trajectory.empty() || a.octomap.empty()) throw Error(std::string("score needs --trajectory and --octomap\n") + kUsage);
  const Config cfg = loadConfig(a);
  const CameraModel cam = CameraModel::load(cfg);
  const mapping::DenseMapOptions dense = mapping::DenseMapOptions::load(cfg);
  double res = 0;
  const std::vector<Eigen::Vector3d> occupied = mapping::readOctomapOccupied(a.octomap, &res);
  const io::TumSequence seq = io::TumSequence::open(a.sequence);
  const Trajectory traj = io::readTrajectory(a.trajectory);
  VoxelSet stat, person;
  long frames = 0;
  for (size_t i = 0; i < seq.size(); i += a.step) {
    const StampedPose* T = poseAt(traj, seq.frames()[i].rgb_stamp);
    if (!T) continue;
    ++frames;
    const cv::Mat depth = seq.loadDepth(i, cam.depth_map_factor);
    const cv::Mat gt = loadGtMask(seq, i);
    for (int v = dense.pixel_stride / 2; v < depth.rows; v += dense.pixel_stride)
      for (int u = dense.pixel_stride / 2; u < depth.cols; u += dense.pixel_stride) {
        const float d = depth.at<float>(v, u);
        if (!(d > 0)) continue;
        const Eigen::Vector3d pc = cam.unproject(u, v, d);
        if (pc.norm() > dense.max_range_m) continue;  // the map's range along the ray
        const uint64_t key = voxelOf(T->T_wc * pc, res);
        const uint8_t g = gt.at<uint8_t>(v, u);
        if (g == 255) person.insert(key);
        else if (g < kMaskDynamic) stat.insert(key);
      }
  }
  if (frames == 0) throw Error(a.trajectory + ": no pose at the sequence's frame stamps; pass the run's CameraTrajectory.txt");
  VoxelSet occ;
  long on_people = 0, off_static = 0;
  for (const Eigen::Vector3d& c : occupied) {
    occ.insert(voxelOf(c, res));
    if (near(stat, c, res, kStaticToleranceVoxels)) continue;
    ++off_static;
    on_people += person.count(voxelOf(c, res)) ? 1 : 0;
  }
  long covered = 0;
  for (uint64_t k : stat) covered += near(occ, centreOf(k, res), res, kCoverageRadiusVoxels);
  const long n_occ = static_cast<long>(occupied.size()), n_stat = static_cast<long>(stat.size());
  return Json{{"frames", frames},
              {"resolution_m", res},
              {"occupied_voxels", n_occ},
              {"on_people", on_people},
              {"on_people_share", jsonRatio(on_people, n_occ)},
              {"off_static", off_static},
              {"off_static_share", jsonRatio(off_static, n_occ)},
              {"static_voxels", n_stat},
              {"static_covered_within_2", covered},
              {"static_coverage", jsonRatio(covered, n_stat)}};
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Args a = parseArgs(argc, argv);
    Json j;
    if (a.command == "mask") j = runMask(a);
    else if (a.command == "score") j = runScore(a);
    else throw Error("unknown command '" + a.command + "'\n" + kUsage);
    std::printf("%s\n", dumpJson(j).c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
