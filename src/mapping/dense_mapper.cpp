#include "yolo_slam/mapping/dense_mapper.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/log.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/common/thread_name.h"

#include <chrono>
#include <cstdio>
#include <utility>

namespace yolo_slam {
namespace mapping {

namespace {
// How often an idle mapper looks at the map version (a loop closed with no keyframe after it).
constexpr std::chrono::milliseconds kVersionPoll(200);
constexpr double kBytesPerMb = 1024.0 * 1024.0;
}  // namespace

void to_json(Json& j, const DenseMapStats& s) {
  j = Json{{"keyframes", s.keyframes},
           {"dropped", s.dropped},
           {"rebuilds", s.rebuilds},
           {"voxels", s.voxels},
           {"points", s.points},
           {"memory_mb", jsonNumber(s.memory_bytes / kBytesPerMb)},
           {"mask_ms", summaryJsonMs(summarize(s.mask_ms))},
           {"integration_ms", summaryJsonMs(summarize(s.integration_ms))},
           {"integration_cpu_ms", summaryJsonMs(summarize(s.integration_cpu_ms))},
           {"rebuild_ms", summaryJsonMs(summarize(s.rebuild_ms))}};
}

DenseMapper::DenseMapper(const CameraModel& cam, const DenseMapOptions& options,
                         const screening::ScreeningOptions& screening, bool threaded, MapVersion version)
    : cam_(cam), opt_(options), screener_(screening), threaded_(threaded), version_(std::move(version)),
      map_(cam, options) {
  if (version_) seen_version_ = version_();
}

DenseMapper::~DenseMapper() { stop(); }

void DenseMapper::start() {
  std::lock_guard<std::mutex> lk(queue_mutex_);
  if (!threaded_ || running_ || stop_) return;
  running_ = true;
  thread_ = std::thread([this] {
    nameThisThread("ys_dense_map");
    lowerThisThreadPriority(opt_.thread_nice, "DenseMap.threadNice");
    run();
  });
}

void DenseMapper::stop() {
  {
    std::lock_guard<std::mutex> lk(queue_mutex_);
    if (finished_) return;
    finished_ = true;
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  processQueued();  // what a thread never started left
  if (opt_.final_rebuild || versionMoved()) rebuild();
}

void DenseMapper::insert(DenseKeyFrame kf) {
  kf.generation = generation_.load();
  {
    std::lock_guard<std::mutex> lk(queue_mutex_);
    if (stop_) return;
    if (queue_.size() >= static_cast<size_t>(opt_.queue_size)) {
      queue_.pop_front();
      ++dropped_;
    }
    queue_.push_back(std::move(kf));
  }
  cv_.notify_all();
}

void DenseMapper::run() {
  std::unique_lock<std::mutex> lk(queue_mutex_);
  while (true) {
    cv_.wait_for(lk, kVersionPoll, [this] { return stop_ || !queue_.empty(); });
    const bool have = !queue_.empty();
    if (!have && stop_) break;
    DenseKeyFrame kf;
    if (have) {
      kf = std::move(queue_.front());
      queue_.pop_front();
    }
    lk.unlock();
    if (have) processOne(kf);
    if (versionMoved()) rebuild();
    lk.lock();
  }
}

void DenseMapper::processQueued() {
  while (true) {
    DenseKeyFrame kf;
    {
      std::lock_guard<std::mutex> lk(queue_mutex_);
      if (queue_.empty()) break;
      kf = std::move(queue_.front());
      queue_.pop_front();
    }
    processOne(kf);
  }
  if (versionMoved()) rebuild();
}

void DenseMapper::clear() {
  generation_.fetch_add(1);
  {
    std::lock_guard<std::mutex> lk(queue_mutex_);
    queue_.clear();
  }
  std::lock_guard<std::mutex> lk(map_mutex_);
  map_.clear();
  kept_.clear();
}

bool DenseMapper::versionMoved() {
  if (!version_) return false;
  const long v = version_();
  if (v == seen_version_) return false;
  seen_version_ = v;
  return true;
}

void DenseMapper::processOne(DenseKeyFrame& kf) {
  Stopwatch sw;
  auto cloud = std::make_shared<KeyFrameCloud>();
  try {
    const cv::Mat mask = opt_.mask_people ? staticMask(kf.depth_m, kf.boxes, screener_, opt_.mask)
                                          : cv::Mat(kf.depth_m.size(), CV_8UC1, cv::Scalar(255));
    const double mask_ms = sw.ms();
    *cloud = backProject(cam_, opt_, kf.image, kf.depth_m, mask);
    const std::optional<Pose> T_wc = kf.pose ? kf.pose() : std::nullopt;
    if (!T_wc || !T_wc->matrix().allFinite()) return;  // keyframe gone from the map meanwhile
    std::lock_guard<std::mutex> lk(map_mutex_);
    if (kf.generation != generation_.load()) return;
    Stopwatch si;
    const double cpu0 = threadCpuMs();
    map_.integrate(*cloud, *T_wc);
    kept_[kf.id] = Kept{kf.pose, cloud};
    ++stats_.keyframes;
    stats_.mask_ms.push_back(mask_ms);
    stats_.integration_ms.push_back(si.ms());
    stats_.integration_cpu_ms.push_back(threadCpuMs() - cpu0);
  } catch (const Error& e) {
    log::warn("dense map: keyframe %ld (%.6f) not integrated: %s", kf.id, kf.stamp, e.what());
  }
}

namespace {
// Integrates every keyframe of `todo` with its current pose into `map`; returns the ids whose
// keyframe is gone. No lock held: the pose getters take the SLAM map's mutex.
template <class Kept>
std::vector<long> integrateAll(const std::map<long, Kept>& todo, DenseMap& map) {
  std::vector<long> gone;
  for (const auto& kv : todo) {
    const std::optional<Pose> T_wc = kv.second.pose();
    if (T_wc && T_wc->matrix().allFinite())
      map.integrate(*kv.second.cloud, *T_wc);
    else
      gone.push_back(kv.first);
  }
  return gone;
}
}  // namespace

void DenseMapper::rebuild() {
  Stopwatch sw;
  const long generation = generation_.load();
  DenseMap fresh(cam_, opt_);
  std::map<long, Kept> done, todo;
  std::vector<long> gone;
  {
    std::lock_guard<std::mutex> lk(map_mutex_);
    todo = kept_;
  }
  // Keyframes integrated into map_ while this ran are not in `fresh` yet: loop until none is new.
  while (true) {
    for (long id : integrateAll(todo, fresh)) gone.push_back(id);
    done.insert(todo.begin(), todo.end());
    todo.clear();
    std::lock_guard<std::mutex> lk(map_mutex_);
    if (generation != generation_.load()) return;
    for (const auto& kv : kept_)
      if (!done.count(kv.first)) todo.insert(kv);
    if (!todo.empty()) continue;
    for (long id : gone) kept_.erase(id);
    map_ = std::move(fresh);
    ++stats_.rebuilds;
    stats_.rebuild_ms.push_back(sw.ms());
    return;
  }
}

DenseMapStats DenseMapper::stats() const {
  DenseMapStats s;
  {
    std::lock_guard<std::mutex> lk(map_mutex_);
    s = stats_;
    s.voxels = map_.occupiedVoxels();
    s.points = map_.cloud().size();
    s.memory_bytes = map_.memoryBytes();
    for (const auto& kv : kept_) s.memory_bytes += kv.second.cloud->bytes();
  }
  std::lock_guard<std::mutex> lk(queue_mutex_);
  s.dropped = dropped_;
  return s;
}

std::vector<Voxel> DenseMapper::occupiedLeaves() const {
  std::lock_guard<std::mutex> lk(map_mutex_);
  return map_.occupiedLeaves();
}

std::vector<Voxel> DenseMapper::freeLeaves() const {
  std::lock_guard<std::mutex> lk(map_mutex_);
  return map_.freeLeaves();
}

std::vector<ColouredPoint> DenseMapper::cloud() const {
  std::lock_guard<std::mutex> lk(map_mutex_);
  return map_.cloud();
}

std::vector<Eigen::Vector3d> DenseMapper::occupiedCentres() const {
  std::lock_guard<std::mutex> lk(map_mutex_);
  return map_.occupiedCentres();
}

void DenseMapper::writeOctomap(const std::string& path) const {
  std::lock_guard<std::mutex> lk(map_mutex_);
  map_.writeOctomap(path);
}

void DenseMapper::writeCloud(const std::string& path) const { writePly(path, cloud()); }

}  // namespace mapping
}  // namespace yolo_slam
