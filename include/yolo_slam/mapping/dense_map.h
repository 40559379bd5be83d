#pragma once
// A dense map of the static scene: keyframes' static depth (mapping/static_mask.h), back-projected
// with their poses into an OctoMap occupancy tree with ray-cast free space (a person who walked
// through is carved away again by the rays that later see the wall behind), plus a coloured
// point cloud downsampled to a voxel grid, of which only the points in occupied voxels are
// output. Single-threaded: mapping::DenseMapper owns one and runs it in its own thread.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/common/json.h"
#include "yolo_slam/mapping/static_mask.h"

#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace octomap {
class OcTree;
}

namespace yolo_slam {

class Config;

namespace mapping {

struct DenseMapOptions {
  static constexpr double kDefaultResolutionM = 0.05;
  static constexpr double kDefaultMaxRangeM = 4.0;
  static constexpr int kDefaultPixelStride = 4;
  static constexpr double kDefaultCloudResolutionM = 0.02;
  static constexpr int kDefaultQueueSize = 8;
  static constexpr double kDefaultProbHit = 0.7;   // OctoMap's defaults
  static constexpr double kDefaultProbMiss = 0.4;

  bool enabled = false;                              // DenseMap.enabled
  double resolution_m = kDefaultResolutionM;         // DenseMap.resolution: octree voxel edge
  double max_range_m = kDefaultMaxRangeM;            // DenseMap.maxRange: range along the ray;
                                                     // farther points only carve free space
                                                     // up to it
  int pixel_stride = kDefaultPixelStride;            // DenseMap.pixelStride: every N-th pixel
                                                     // of every N-th row is integrated
  double cloud_resolution_m = kDefaultCloudResolutionM;  // DenseMap.cloudResolution
  double prob_hit = kDefaultProbHit;                 // DenseMap.probHit
  double prob_miss = kDefaultProbMiss;               // DenseMap.probMiss
  int queue_size = kDefaultQueueSize;                // DenseMap.queueSize: keyframes waiting;
                                                     // when full the oldest waiting is dropped
  int thread_nice = 10;                              // DenseMap.threadNice: the mapper thread's
                                                     // nice value above the process's
  bool final_rebuild = true;                         // DenseMap.finalRebuild: at the end, all
                                                     // keyframes again with their final poses
  bool mask_people = true;                           // DenseMap.maskPeople: 0 integrates every
                                                     // pixel (a plain fusion, for comparison)
  StaticMaskOptions mask;                            // DenseMap.maskMargin, maskSampleStride

  // Reads the DenseMap.* keys; invalid values throw yolo_slam::Error naming the file and key.
  static DenseMapOptions load(const Config& cfg);
  // The loader's rules for options set in code; throws yolo_slam::Error prefixed by `where`.
  void validate(const std::string& where = "DenseMapOptions") const;
};

// One keyframe's static depth in its camera frame, kept for re-integration after a pose change.
struct KeyFrameCloud {
  std::vector<Eigen::Vector3f> points;            // static pixels within max range (ray length)
  std::vector<std::array<uint8_t, 3>> rgb;        // their colour
  std::vector<Eigen::Vector3f> beyond;            // static pixels beyond max range: free space only
  size_t bytes() const;
};

// Back-projects the static pixels (static_mask 255) of every pixel_stride-th pixel. image: BGR
// or RGB (cam.rgb_order) CV_8UC3, or CV_8UC1 grey, or empty (grey points); depth_m CV_32FC1.
// Pixels are undistorted with the camera's model. Throws yolo_slam::Error on sizes that differ.
KeyFrameCloud backProject(const CameraModel& cam, const DenseMapOptions& o, const cv::Mat& image,
                          const cv::Mat& depth_m, const cv::Mat& static_mask);

struct ColouredPoint {
  Eigen::Vector3f p;
  std::array<uint8_t, 3> rgb;
};

// An occupied leaf of the octree: centre and edge length (pruned leaves are larger).
struct Voxel {
  Eigen::Vector3d centre;
  double size = 0;
};

// A 2D occupancy grid from the octree's leaves in a height band (nav_msgs/OccupancyGrid's
// convention: row-major from the origin, -1 unknown, 0 free, 100 occupied). A cell is occupied
// when an occupied leaf in the band covers it, free when only free leaves do.
struct OccupancyGrid2D {
  static constexpr int8_t kUnknown = -1, kFree = 0, kOccupied = 100;
  double resolution = 0;
  double origin_x = 0, origin_y = 0;  // metres, corner of cell (0, 0)
  int width = 0, height = 0;
  std::vector<int8_t> cells;
};

// Projects leaves (centres already in the frame whose z is up, e.g. the ROS map frame) with
// z_min <= z <= z_max onto the x-y plane at `resolution`; empty grid when none is in the band.
OccupancyGrid2D projectToGrid(const std::vector<Voxel>& occupied, const std::vector<Voxel>& free,
                              double z_min, double z_max, double resolution);

class DenseMap {
 public:
  DenseMap(const CameraModel& cam, const DenseMapOptions& options);  // validates the options
  ~DenseMap();
  DenseMap(DenseMap&&) noexcept;
  DenseMap& operator=(DenseMap&&) noexcept;

  // Rays from the camera centre of T_wc to every point: free on the way, occupied at the end
  // (points beyond max range: free up to it).
  void integrate(const KeyFrameCloud& cloud, const Pose& T_wc);
  void clear();

  std::vector<Voxel> occupiedLeaves() const;
  std::vector<Voxel> freeLeaves() const;
  // Occupied voxels at the finest resolution (pruned leaves expanded).
  size_t occupiedVoxels() const;
  // One point per cloud voxel (mean position and colour) whose octree voxel is occupied.
  std::vector<ColouredPoint> cloud() const;
  // Occupied voxels at the finest resolution, their centres: for scoring against ground truth.
  std::vector<Eigen::Vector3d> occupiedCentres() const;
  // Octree plus cloud voxels (bytes; the stored keyframe clouds are the mapper's).
  size_t memoryBytes() const;
  const octomap::OcTree& tree() const { return *tree_; }
  const DenseMapOptions& options() const { return opt_; }

  // OctoMap's binary format (.bt: maximum-likelihood occupancy; octovis, octomap's readBinary).
  // Throws yolo_slam::Error naming the file when it cannot be written.
  void writeOctomap(const std::string& path) const;

 private:
  struct CloudCell {
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    std::array<uint32_t, 3> rgb{{0, 0, 0}};
    uint32_t n = 0;
  };
  uint64_t cloudKey(const Eigen::Vector3f& p) const;
  // Updates the inner nodes and prunes after lazy insertions; every output calls it first.
  void syncInner() const;

  CameraModel cam_;
  DenseMapOptions opt_;
  std::unique_ptr<octomap::OcTree> tree_;
  std::unordered_map<uint64_t, CloudCell> cells_;
  // Lazy insertion state: the tree (behind the pointer) is brought up to date by syncInner().
  mutable bool inner_stale_ = false;
  mutable int scans_since_inner_ = 0;
};

// Binary little-endian PLY (vertex x y z float, red green blue uchar). Throws yolo_slam::Error
// naming the file when it cannot be written.
void writePly(const std::string& path, const std::vector<ColouredPoint>& points);
// Reads what writePly wrote (and any PLY with that vertex layout, binary little-endian or
// ASCII). Throws yolo_slam::Error naming the file and what is wrong.
std::vector<ColouredPoint> readPly(const std::string& path);
// Occupied voxel centres at the tree's finest resolution of a .bt file, and the resolution.
// Throws yolo_slam::Error naming the file when octomap cannot read it.
std::vector<Eigen::Vector3d> readOctomapOccupied(const std::string& path, double* resolution = nullptr);

}  // namespace mapping
}  // namespace yolo_slam
