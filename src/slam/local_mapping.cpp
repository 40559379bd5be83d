#include "yolo_slam/slam/local_mapping.h"

#include "yolo_slam/common/timing.h"
#include "yolo_slam/optimization/bundle_adjustment.h"
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/loop_closing.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/slam/matcher.h"
#include "yolo_slam/slam/observation.h"
#include "yolo_slam/slam/triangulation.h"
#include "yolo_slam/common/thread_name.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <unordered_map>

namespace yolo_slam {
namespace slam {

LocalMapping::LocalMapping(Map& map, const CameraModel& cam, const LocalMappingOptions& opt,
                           std::shared_ptr<const vocabulary::Vocabulary> vocabulary, RunMode mode)
    : map_(map), cam_(cam), opt_(opt), voc_(std::move(vocabulary)), mode_(mode) {
  if (opt_.queue_size < 1) opt_.queue_size = 1;
}

LocalMapping::~LocalMapping() { stop(); }

void LocalMapping::start() {
  std::lock_guard<std::mutex> lk(queue_mutex_);
  if (thread_.joinable()) return;
  stop_ = false;
  if (mode_ == RunMode::Threaded) thread_ = std::thread([this] {
    nameThisThread("ys_local_map");
    run();
  });
}

void LocalMapping::stop() {
  {
    std::lock_guard<std::mutex> lk(queue_mutex_);
    stop_ = true;
    abort_ba_.store(true);
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool LocalMapping::insertKeyFrame(const KeyFramePtr& kf) {
  {
    std::lock_guard<std::mutex> lk(queue_mutex_);
    if (static_cast<int>(queue_.size()) >= opt_.queue_size) return false;
    queue_.push_back(kf);
    abort_ba_.store(true);
    accept_.store(false);
  }
  cv_.notify_all();
  return true;
}

size_t LocalMapping::queued() const {
  std::lock_guard<std::mutex> lk(queue_mutex_);
  return queue_.size();
}

void LocalMapping::requestPause(std::atomic<bool>& flag) {
  flag.store(true);
  abort_ba_.store(true);
  cv_.notify_all();
}

void LocalMapping::releasePause(std::atomic<bool>& flag) {
  {
    std::lock_guard<std::mutex> lk(queue_mutex_);
    flag.store(false);
  }
  cv_.notify_all();
}

void LocalMapping::pause() { requestPause(pause_requested_); }
void LocalMapping::resume() { releasePause(pause_requested_); }
void LocalMapping::pauseForLoop() { requestPause(loop_pause_); }
void LocalMapping::resumeFromLoop() { releasePause(loop_pause_); }

void LocalMapping::waitUntilPaused() {
  std::unique_lock<std::mutex> lk(queue_mutex_);
  if (!thread_.joinable()) return;
  cv_.wait(lk, [this] { return paused_ack_ || stop_ || !pauseWanted(); });
}

void LocalMapping::waitIdle() {
  std::unique_lock<std::mutex> lk(queue_mutex_);
  if (!thread_.joinable()) return;
  cv_.wait(lk, [this] { return stop_ || paused_ack_ || (queue_.empty() && !busy_); });
}

void LocalMapping::clear() {
  std::lock_guard<std::mutex> lk(queue_mutex_);
  queue_.clear();
  recent_points_.clear();
  current_.reset();
  accept_.store(true);
}

std::vector<double> LocalMapping::timings() const { return phaseTimings().total; }
LocalMappingTimings LocalMapping::phaseTimings() const { return lockedCopy(queue_mutex_, timings_); }
size_t LocalMapping::processedKeyFrames() const { return lockedCopy(queue_mutex_, processed_); }
size_t LocalMapping::culledKeyFrames() const { return lockedCopy(queue_mutex_, culled_); }

void LocalMapping::run() {
  std::unique_lock<std::mutex> lk(queue_mutex_);
  while (true) {
    cv_.wait(lk, [this] { return stop_ || pauseWanted() || !queue_.empty(); });
    if (stop_) break;
    if (pauseWanted()) {
      paused_ack_ = true;
      accept_.store(false);
      cv_.notify_all();
      cv_.wait(lk, [this] { return stop_ || !pauseWanted(); });
      paused_ack_ = false;
      accept_.store(queue_.empty());
      continue;
    }
    processFront(lk);
  }
  busy_ = false;
  cv_.notify_all();
}

void LocalMapping::processQueued() {
  if (mode_ != RunMode::Sequential) return;
  std::unique_lock<std::mutex> lk(queue_mutex_);
  while (!stop_ && !pauseWanted() && !queue_.empty()) processFront(lk);
}

void LocalMapping::processFront(std::unique_lock<std::mutex>& lk) {
  KeyFramePtr kf = queue_.front();
  queue_.pop_front();
  busy_ = true;
  accept_.store(false);
  lk.unlock();
  Stopwatch sw;
  processOne(kf);
  const double ms = sw.ms();
  lk.lock();
  busy_ = false;
  timings_.total.push_back(ms);
  timings_.insert.push_back(phase_insert_);
  timings_.fuse.push_back(phase_fuse_);
  timings_.ba.push_back(phase_ba_);
  timings_.culling.push_back(phase_culling_);
  ++processed_;
  if (queue_.empty()) accept_.store(true);
  cv_.notify_all();
}

namespace {

bool queueEmpty(std::mutex& m, const std::deque<KeyFramePtr>& q) {
  std::lock_guard<std::mutex> lk(m);
  return q.empty();
}
}  // namespace

void LocalMapping::processOne(const KeyFramePtr& kf) {
  current_ = kf;
  phase_insert_ = phase_fuse_ = phase_ba_ = phase_culling_ = 0;
  Stopwatch sw;
  {
    std::unique_lock<std::mutex> lk(map_.update_mutex);
    sw.restart();
    processNewKeyFrame();
    mapPointCulling();
    createNewMapPoints(lk);
    phase_insert_ = sw.ms();
  }
  if (queueEmpty(queue_mutex_, queue_)) {
    std::unique_lock<std::mutex> lk(map_.update_mutex);
    sw.restart();
    searchInNeighbors(lk);
    phase_fuse_ = sw.ms();
  }
  abort_ba_.store(false);
  if (queueEmpty(queue_mutex_, queue_) && !pauseWanted()) {
    sw.restart();
    if (opt_.local_ba) localBundleAdjustment();
    phase_ba_ = sw.ms();
    std::lock_guard<std::mutex> lk(map_.update_mutex);
    sw.restart();
    keyFrameCulling();
    phase_culling_ = sw.ms();
  }
  if (loop_closer_) loop_closer_->insertKeyFrame(current_);  // it checks `bad` under the map lock
  current_.reset();
}

void LocalMapping::processNewKeyFrame() {
  KeyFrame& kf = *current_;
  computeBow(voc_.get(), kf.f);
  for (size_t i = 0; i < kf.f.points.size(); ++i) {
    MapPointPtr mp = kf.f.points[i];
    if (!mp) continue;
    if (mp->bad || kf.f.dynamic[i]) {
      kf.f.points[i].reset();
      continue;
    }
    auto it = mp->observations.find(current_);
    if (it == mp->observations.end()) {
      Map::addObservation(mp, current_, i);
      mp->updateNormalAndDepth();
      mp->computeDistinctiveDescriptor();
    } else if (it->second != i) {
      kf.f.points[i].reset();  // the same point on two keypoints: keep the first association
    } else {
      recent_points_.push_back(mp);  // created by Tracking for this keyframe
    }
  }
  kf.updateConnections();
  map_.addKeyFrame(current_);
}

void LocalMapping::mapPointCulling() {
  // ORB-SLAM2 MapPointCulling (stereo/RGB-D): a new point goes if found in less than this share
  // of the frames that should see it, or if kCullAfterKeyFrames keyframes after its creation it
  // has at most kCullMaxObservations (weighted) observations; after kKeepAfterKeyFrames it
  // has proven itself.
  constexpr double kMinFoundRatio = 0.25;
  constexpr long kCullAfterKeyFrames = 2;
  constexpr int kCullMaxObservations = 3;
  constexpr long kKeepAfterKeyFrames = 3;
  const long cur = current_->id;
  for (auto it = recent_points_.begin(); it != recent_points_.end();) {
    const MapPointPtr& mp = *it;
    if (mp->bad) {
      it = recent_points_.erase(it);
    } else if (mp->foundRatio() < kMinFoundRatio) {
      map_.eraseMapPoint(mp);
      it = recent_points_.erase(it);
    } else if (cur - mp->first_kf_id >= kCullAfterKeyFrames &&
               !mp->weightedObservationsAtLeast(kCullMaxObservations + 1)) {
      map_.eraseMapPoint(mp);
      it = recent_points_.erase(it);
    } else if (cur - mp->first_kf_id >= kKeepAfterKeyFrames) {
      it = recent_points_.erase(it);
    } else {
      ++it;
    }
  }
}

void LocalMapping::createNewMapPoints(std::unique_lock<std::mutex>& map_lock) {
  const KeyFramePtr& kf1 = current_;
  const std::vector<KeyFramePtr> neigh = kf1->bestCovisibles(opt_.triangulation_neighbours);
  const TriangulationView v1(*kf1);
  const Eigen::Matrix3d K = (Eigen::Matrix3d() << cam_.fx, 0, cam_.cx, 0, cam_.fy, cam_.cy, 0, 0, 1).finished();
  const Eigen::Matrix3d Kinv = K.inverse();
  for (const KeyFramePtr& kf2 : neigh) {
    if (kf2 != neigh.front()) map_.yieldToTracking(map_lock);
    if (kf2->bad || current_->bad) continue;
    if (!queueEmpty(queue_mutex_, queue_) && kf2 != neigh.front()) break;
    const TriangulationView v2(*kf2);
    if ((v2.O - v1.O).norm() < cam_.baseline()) continue;
    const Pose T21 = v2.T * v1.T.inverse();
    const Eigen::Matrix3d F21 = Kinv.transpose() * skew(T21.translation()) * T21.linear() * Kinv;
    for (const auto& m : matcher::searchForTriangulation(*kf1, *kf2, F21)) {
      Eigen::Vector3d X;
      if (!triangulateMatch(cam_, v1, v2, m.first, m.second, opt_.free_space_ratio, X)) continue;
      auto mp = std::make_shared<MapPoint>(map_.newPointId(), X, kf1.get(), kf1->frame_id);
      Map::addObservation(mp, kf1, m.first);
      Map::addObservation(mp, kf2, m.second);
      mp->computeDistinctiveDescriptor();
      mp->updateNormalAndDepth();
      map_.addMapPoint(mp);
      recent_points_.push_back(mp);
    }
  }
}

void LocalMapping::searchInNeighbors(std::unique_lock<std::mutex>& map_lock) {
  const KeyFramePtr& cur = current_;
  if (cur->bad) return;
  std::vector<KeyFramePtr> targets;
  std::set<long> seen{cur->id};
  for (const auto& kf : cur->bestCovisibles(opt_.fuse_neighbours)) {
    if (kf->bad || !seen.insert(kf->id).second) continue;
    targets.push_back(kf);
  }
  // ORB-SLAM2 SearchInNeighbors: the best covisibles of each neighbour are targets too.
  constexpr size_t kFuseSecondNeighbours = 5;
  const size_t n1 = targets.size();
  for (size_t k = 0; k < n1; ++k)
    for (const auto& kf2 : targets[k]->bestCovisibles(kFuseSecondNeighbours))
      if (!kf2->bad && seen.insert(kf2->id).second) targets.push_back(kf2);

  std::vector<MapPointPtr> cur_points = cur->mapPoints();
  for (const auto& kf : targets) {
    map_.yieldToTracking(map_lock);
    if (cur->bad) return;
    if (!kf->bad) matcher::fuse(map_, kf, cur_points);
  }
  map_.yieldToTracking(map_lock);
  if (cur->bad) return;

  std::vector<MapPointPtr> candidates;
  std::set<long> cand_ids;
  for (const auto& kf : targets)
    for (const auto& mp : kf->mapPoints())
      if (!mp->dynamic && cand_ids.insert(mp->id).second) candidates.push_back(mp);
  matcher::fuse(map_, cur, candidates);

  for (const auto& mp : cur->mapPoints()) {
    mp->computeDistinctiveDescriptor();
    mp->updateNormalAndDepth();
  }
  cur->updateConnections();
}

namespace {

// The local BA window and the map objects behind its indices.
struct LocalWindow {
  optimization::BaProblem problem;
  std::vector<KeyFramePtr> kfs;                    // index = problem.keyframes index
  std::vector<MapPointPtr> points;                 // index = problem.points index
  std::vector<std::pair<size_t, size_t>> obs_ref;  // (kf index, point index) per observation
};

// The current keyframe and its covisibles (free), the points they see, and the other keyframes
// seeing those points (fixed). Caller holds update_mutex.
LocalWindow localWindow(const KeyFramePtr& current) {
  LocalWindow w;
  std::unordered_map<long, size_t> kf_index;
  auto add_kf = [&](const KeyFramePtr& kf, bool fixed) {
    kf_index[kf->id] = w.kfs.size();
    w.kfs.push_back(kf);
    w.problem.keyframes.push_back({kf->id, kf->Tcw(), fixed || kf->is_origin});
  };
  add_kf(current, false);
  for (const auto& kf : current->ordered_connections)
    if (!kf->bad && !kf_index.count(kf->id)) add_kf(kf, false);
  const size_t n_local = w.kfs.size();
  std::set<long> point_ids;
  for (size_t k = 0; k < n_local; ++k) {
    for (const auto& mp : w.kfs[k]->f.points) {
      if (!mp || mp->bad || mp->dynamic || !point_ids.insert(mp->id).second) continue;
      w.points.push_back(mp);
    }
  }
  for (const auto& mp : w.points)
    for (const auto& o : mp->observations)
      if (!o.first->bad && !kf_index.count(o.first->id)) add_kf(o.first, true);
  for (size_t p = 0; p < w.points.size(); ++p) {
    const auto& mp = w.points[p];
    w.problem.points.push_back({mp->id, mp->Xw});
    for (const auto& o : mp->observations) {
      if (o.first->bad) continue;
      w.problem.observations.push_back(baObservation(o.first->f, o.second, o.first->id, mp->id));
      w.obs_ref.emplace_back(kf_index[o.first->id], p);
    }
  }
  return w;
}

// Erases the outlier observations, then writes the free poses and the points. Caller holds
// update_mutex.
void writeBackLocalWindow(Map& map, const LocalWindow& w, const optimization::BaResult& result) {
  for (size_t k = 0; k < w.obs_ref.size() && k < result.outlier_observation.size(); ++k) {
    if (!result.outlier_observation[k]) continue;
    const KeyFramePtr& kf = w.kfs[w.obs_ref[k].first];
    const MapPointPtr& mp = w.points[w.obs_ref[k].second];
    if (mp->bad || kf->bad) continue;
    map.eraseObservation(mp, kf);
  }
  for (size_t k = 0; k < w.kfs.size(); ++k) {
    const auto& bk = w.problem.keyframes[k];
    if (bk.fixed || w.kfs[k]->bad || !bk.T_cw.matrix().allFinite()) continue;
    w.kfs[k]->f.T_cw = bk.T_cw;
  }
  for (size_t p = 0; p < w.points.size(); ++p) {
    const auto& mp = w.points[p];
    if (mp->bad || !w.problem.points[p].Xw.allFinite()) continue;
    mp->Xw = w.problem.points[p].Xw;
    mp->updateNormalAndDepth();
  }
}

}  // namespace

void LocalMapping::localBundleAdjustment() {
  LocalWindow w;
  {
    std::lock_guard<std::mutex> lk(map_.update_mutex);
    if (current_->bad || map_.numKeyFrames() <= 2) return;
    w = localWindow(current_);
  }
  if (w.problem.observations.empty() || abort_ba_.load()) return;
  // Only the solve runs niced (LocalMapping.threadNice): the other phases hold the map lock.
  optimization::BaResult result;
  const int nice = mode_ == RunMode::Threaded ? opt_.thread_nice : 0;
  runAtLowerPriority(nice, "ys_local_ba", "LocalMapping.threadNice",
                     [&] { result = optimization::localBundleAdjustment(cam_, w.problem, abort_ba_); });
  std::lock_guard<std::mutex> lk(map_.update_mutex);
  writeBackLocalWindow(map_, w, result);
}

void LocalMapping::keyFrameCulling() {
  if (current_->bad) return;
  const double close = cam_.closeDepth();
  // ORB-SLAM2 KeyFrameCulling: a point is redundant when this many other keyframes see it at
  // the same or a finer scale.
  const int th_obs = 3;
  std::vector<KeyFramePtr> local = current_->ordered_connections;
  for (const auto& kf : local) {
    if (kf->bad || kf->is_origin || kf->not_erase) continue;
    int n_points = 0, redundant = 0;
    for (size_t i = 0; i < kf->f.points.size(); ++i) {
      const MapPointPtr& mp = kf->f.points[i];
      if (!mp || mp->bad) continue;
      // RGB-D: only close points count (far ones are not reliable to judge redundancy).
      if (kf->f.depth[i] > close || kf->f.depth[i] < 0) continue;
      ++n_points;
      if (!mp->weightedObservationsAtLeast(th_obs + 1)) continue;
      const int level = kf->f.kps[i].octave;
      int n = 0;
      for (const auto& o : mp->observations) {
        if (o.first == kf) continue;
        if (o.first->f.kps[o.second].octave <= level + 1 && ++n >= th_obs) break;
      }
      if (n >= th_obs) ++redundant;
    }
    if (n_points > 0 && redundant > opt_.culling_redundancy * n_points) {
      map_.eraseKeyFrame(kf);
      std::lock_guard<std::mutex> lk(queue_mutex_);
      ++culled_;
    }
  }
}

}  // namespace slam
}  // namespace yolo_slam
