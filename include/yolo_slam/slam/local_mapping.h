#pragma once
// Local mapping (owned by System; own thread, or inline in RunMode::Sequential): processes the
// keyframes that Tracking inserts through a bounded queue: associates their points, culls
// recent points, triangulates new points with the best covisible keyframes, fuses duplicates,
// runs local bundle adjustment (Ceres, aborted when a new keyframe arrives) and culls
// redundant keyframes.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/slam/options.h"
#include "yolo_slam/slam/types.h"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <list>
#include <mutex>
#include <thread>
#include <vector>

namespace yolo_slam {
namespace vocabulary {
class Vocabulary;
}
namespace slam {

class LoopClosing;

// Milliseconds per processed keyframe, whole (waits included) and by phase (from taking the map
// lock to letting it go, including the frames it yields to Tracking; the bundle adjustment
// runs without the lock).
struct LocalMappingTimings {
  std::vector<double> total;
  std::vector<double> insert;  // under the map lock: associate, cull recent points, triangulate
  std::vector<double> fuse;    // under the map lock: searchInNeighbors (skipped while busy)
  std::vector<double> ba;      // local BA without the lock, plus its write-back under it
  std::vector<double> culling; // under the map lock: keyframe culling
};

class LocalMapping {
 public:
  LocalMapping(Map& map, const CameraModel& cam, const LocalMappingOptions& opt,
               std::shared_ptr<const vocabulary::Vocabulary> vocabulary,
               RunMode mode = RunMode::Threaded);
  ~LocalMapping();
  LocalMapping(const LocalMapping&) = delete;
  LocalMapping& operator=(const LocalMapping&) = delete;

  void start();          // spawns the thread (idempotent); Sequential: no thread
  void stop();           // finishes the keyframe in progress, joins; queued ones are dropped
  // Sequential mode: processes every queued keyframe in the caller's thread, as the thread
  // would (timings, counters, acceptsKeyFrames); returns at once while paused or stopped and
  // does nothing in Threaded mode. The caller must NOT hold map.update_mutex.
  void processQueued();

  // Called by Tracking (holding map.update_mutex). Returns false if the queue is full.
  bool insertKeyFrame(const KeyFramePtr& kf);
  bool acceptsKeyFrames() const { return accept_.load(); }
  size_t queued() const;
  int queueCapacity() const { return opt_.queue_size; }
  void interruptBA() { abort_ba_.store(true); }

  // Pausing (localization-only mode, reset): the thread finishes its current keyframe and
  // waits (Sequential: processQueued() leaves the queue alone). waitUntilPaused() blocks until
  // it does (Sequential: returns at once). The caller must NOT hold map.update_mutex.
  void pause();
  void waitUntilPaused();
  void resume();
  // The same pause for loop closing, independent of the one above (a loop correction ending
  // does not resume a mapper parked for localization-only mode or a reset).
  void pauseForLoop();
  void resumeFromLoop();
  bool paused() const { return pauseWanted(); }
  // Every processed keyframe is handed on (set before start(); may be null).
  void setLoopClosing(LoopClosing* lc) { loop_closer_ = lc; }
  // Blocks until the queue is empty and the thread is idle, or paused (Sequential: returns at
  // once). The caller must NOT hold map.update_mutex.
  void waitIdle();
  // Drops queued keyframes and the recent-points list (while paused, for reset).
  void clear();

  // Milliseconds per processed keyframe (copy; thread-safe).
  std::vector<double> timings() const;
  LocalMappingTimings phaseTimings() const;
  size_t processedKeyFrames() const;
  size_t culledKeyFrames() const;

  // One keyframe's whole processing, synchronous (the thread and processQueued() call this;
  // tests may too when the thread is not started).
  void processOne(const KeyFramePtr& kf);

 private:
  void run();
  // Pops the front keyframe and processes it with the bookkeeping around (lk holds
  // queue_mutex_ on entry and on return, released while processing).
  void processFront(std::unique_lock<std::mutex>& lk);
  bool pauseWanted() const { return pause_requested_.load() || loop_pause_.load(); }
  // Sets a pause flag (and aborts a running local BA) / clears it under queue_mutex_.
  void requestPause(std::atomic<bool>& flag);
  void releasePause(std::atomic<bool>& flag);
  void processNewKeyFrame();
  void mapPointCulling();
  // Both hold the map lock (map_lock) and yield it to Tracking between neighbour keyframes.
  void createNewMapPoints(std::unique_lock<std::mutex>& map_lock);
  void searchInNeighbors(std::unique_lock<std::mutex>& map_lock);
  void localBundleAdjustment();
  void keyFrameCulling();

  Map& map_;
  CameraModel cam_;
  LocalMappingOptions opt_;
  std::shared_ptr<const vocabulary::Vocabulary> voc_;
  const RunMode mode_;

  // Guards queue_, busy_, paused_ack_, stop_, timings_, counters. Taken alone or after
  // map.update_mutex (Tracking inserts while holding it), never before it.
  mutable std::mutex queue_mutex_;
  std::condition_variable cv_;
  std::deque<KeyFramePtr> queue_;
  bool busy_ = false;
  bool paused_ack_ = false;
  bool stop_ = false;
  LocalMappingTimings timings_;
  size_t processed_ = 0, culled_ = 0;

  std::atomic<bool> accept_{true};
  std::atomic<bool> abort_ba_{false};
  std::atomic<bool> pause_requested_{false};
  std::atomic<bool> loop_pause_{false};
  LoopClosing* loop_closer_ = nullptr;
  std::thread thread_;

  // Mapping-thread state (only touched by the thread running processOne: the mapping thread,
  // or in Sequential mode the caller of processQueued).
  KeyFramePtr current_;
  std::list<MapPointPtr> recent_points_;
  // Phase times of the keyframe in progress (0 for a phase it skipped).
  double phase_insert_ = 0, phase_fuse_ = 0, phase_ba_ = 0, phase_culling_ = 0;
};

}  // namespace slam
}  // namespace yolo_slam
