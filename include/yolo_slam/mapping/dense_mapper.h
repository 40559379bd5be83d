#pragma once
// The dense-mapping stage: keyframes (pose getter, depth, colour, person boxes) queue here and
// are integrated into a mapping::DenseMap in the mapper's own thread, never the tracking
// thread; without a thread (System.sequential) the caller runs processQueued() after each frame instead
// (deterministic). When the map's poses change (a loop closure or global BA: the map version
// counter moves), every kept keyframe is integrated again, into a fresh map, with its current
// pose. docs/dense-map.md.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/common/json.h"
#include "yolo_slam/detection/box.h"
#include "yolo_slam/mapping/dense_map.h"
#include "yolo_slam/screening/screener.h"

#include <opencv2/core.hpp>

#include <atomic>
#include <condition_variable>
#include <memory>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace yolo_slam {
namespace mapping {

// T_wc of a keyframe now; nullopt when the keyframe is gone from the map (reset). Called by
// the mapper with none of its own locks held (it may take the SLAM map's mutex).
using PoseGetter = std::function<std::optional<Pose>()>;
// A counter that moves whenever keyframe poses were corrected (loops closed + global BAs).
using MapVersion = std::function<long()>;

struct DenseKeyFrame {
  long id = 0;
  double stamp = 0;
  PoseGetter pose;
  cv::Mat image;    // BGR/RGB per Camera.RGB, or grey; owned (the caller hands a copy)
  cv::Mat depth_m;  // CV_32FC1 metres; owned
  detection::Boxes boxes;
  long generation = 0;  // set by insert(): keyframes of a map cleared since are dropped
};

struct DenseMapStats {
  size_t keyframes = 0;        // integrated (first time)
  size_t dropped = 0;          // dropped from a full queue
  size_t rebuilds = 0;         // re-integrations of every keyframe after a pose change
  size_t voxels = 0;           // occupied, finest resolution
  size_t points = 0;           // coloured cloud (occupied voxels only)
  size_t memory_bytes = 0;     // octree + cloud voxels + kept keyframe clouds
  // Wall times; integration_cpu_ms: the mapper thread's CPU time of the same integrations.
  std::vector<double> mask_ms, integration_ms, integration_cpu_ms, rebuild_ms;
};
// {"keyframes", "dropped", "rebuilds", "voxels", "points", "memory_mb", "mask_ms" {...},
//  "integration_ms" {...}, "integration_cpu_ms" {...}, "rebuild_ms" {...}}
void to_json(Json& j, const DenseMapStats& s);

class DenseMapper {
 public:
  // Validates the options; `version` may be null (poses never change). threaded false: no
  // thread, the caller runs processQueued() (deterministic).
  DenseMapper(const CameraModel& cam, const DenseMapOptions& options,
              const screening::ScreeningOptions& screening, bool threaded, MapVersion version);
  ~DenseMapper();  // stop()
  DenseMapper(const DenseMapper&) = delete;
  DenseMapper& operator=(const DenseMapper&) = delete;

  void start();  // threaded: spawns the thread (idempotent); otherwise nothing
  // Integrates what is queued, a pending rebuild, and with finalRebuild all keyframes once more
  // with their final poses; then joins the thread. Idempotent.
  void stop();
  // Never blocks on integration: a full queue drops its oldest keyframe (counted).
  void insert(DenseKeyFrame kf);
  // Without a thread: integrates the queue (and a rebuild the version asks for) in the caller.
  void processQueued();
  // Forgets every keyframe and empties the map (SLAM map reset or replaced).
  void clear();

  const DenseMapOptions& options() const { return opt_; }
  DenseMapStats stats() const;
  // Copies taken under the map lock.
  std::vector<Voxel> occupiedLeaves() const;
  std::vector<Voxel> freeLeaves() const;
  std::vector<ColouredPoint> cloud() const;
  std::vector<Eigen::Vector3d> occupiedCentres() const;
  void writeOctomap(const std::string& path) const;
  void writeCloud(const std::string& path) const;

 private:
  struct Kept {
    PoseGetter pose;
    std::shared_ptr<const KeyFrameCloud> cloud;  // shared with a rebuild in progress
  };
  void run();
  // One keyframe: mask, back-projection, integration. Mapper thread (or processQueued).
  void processOne(DenseKeyFrame& kf);
  // Every kept keyframe into a fresh map with its current pose, swapped in unless a clear()
  // came in between. Mapper thread (or processQueued / stop).
  void rebuild();
  bool versionMoved();

  CameraModel cam_;
  DenseMapOptions opt_;
  screening::Screener screener_;
  const bool threaded_;
  MapVersion version_;
  long seen_version_ = 0;  // mapper thread only (or the caller of processQueued / stop)
  // Bumped by clear() (the caller's thread, as insert()); read by the mapper.
  std::atomic<long> generation_{0};

  // Lock order: queue_mutex_ and map_mutex_ are never held together, and neither while a
  // PoseGetter runs (it takes the SLAM map's mutex).
  mutable std::mutex queue_mutex_;  // guards queue_, stop_, running_, finished_, dropped_
  std::condition_variable cv_;
  std::deque<DenseKeyFrame> queue_;
  bool stop_ = false;
  bool running_ = false;
  bool finished_ = false;  // stop() done
  size_t dropped_ = 0;
  std::thread thread_;

  mutable std::mutex map_mutex_;  // guards map_, kept_, stats_ (but stats_.dropped)
  DenseMap map_;
  std::map<long, Kept> kept_;     // by keyframe id: rebuilds integrate in id order
  DenseMapStats stats_;
};

}  // namespace mapping
}  // namespace yolo_slam
