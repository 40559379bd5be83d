#pragma once
// Loop closing (owned by System; own thread, or inline in RunMode::Sequential): ORB-SLAM2's
// LoopClosing for RGB-D, with SE3 in place of Sim3 (depth gives metric scale). LocalMapping hands
// over every processed keyframe; the thread
//   1. detects loop candidates with the map's KeyFrameDatabase (score above the lowest score of
//      the keyframe's covisibles, covisible keyframes excluded, the candidate's covisibility
//      group consistent over `consistency` consecutive keyframes),
//   2. verifies them geometrically (SearchByBoW, 3D-3D RANSAC with Umeyama/Horn on the map
//      points, pose-only refinement, projection search of the loop side's points: >= min_matches),
//   3. corrects: pauses local mapping, moves the current keyframe's covisible neighbourhood and
//      its points onto the loop side, fuses duplicated points, adds the loop edge, optimises
//      the essential graph (spanning tree + loop edges + covisibility >= covisibility_weight),
//   4. runs global bundle adjustment in a separate thread (aborted by a new loop, reset or
//      shutdown; Sequential: synchronously, to the end) and writes it back, propagating to
//      keyframes created meanwhile via the tree.
//
// LOCKING. Map::update_mutex guards every map object (map.h). This class takes it for the
// detection, the verification and the whole correction, and for the GBA copy/write-back;
// never while waiting for LocalMapping to pause (LocalMapping needs it to finish its step).
// queue_mutex_ guards queue_, busy_, stop_, running_ and the counters; taken alone or after
// update_mutex, never before it. The KeyFrameDatabase mutex is always taken last.
// Order overall: Tracking's System::track_mutex_ > Map::update_mutex > LocalMapping queue
// mutex / LoopClosing::queue_mutex_ > KeyFrameDatabase mutex.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/optimization/bundle_adjustment.h"
#include "yolo_slam/optimization/pose_graph.h"
#include "yolo_slam/slam/options.h"
#include "yolo_slam/slam/types.h"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <random>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

namespace yolo_slam {
namespace slam {

class LocalMapping;

class LoopClosing {
 public:
  // `mapper` (may be null in tests) is paused during a correction.
  LoopClosing(Map& map, const CameraModel& cam, const LoopClosingOptions& opt, LocalMapping* mapper,
              RunMode mode = RunMode::Threaded);
  ~LoopClosing();
  LoopClosing(const LoopClosing&) = delete;
  LoopClosing& operator=(const LoopClosing&) = delete;

  void start();   // spawns the thread (idempotent); Sequential: accepts keyframes, no thread
  // Stops the thread and any global BA (aborted, not written back); queued keyframes dropped.
  void stop();
  // Called by LocalMapping after a keyframe is processed (no map lock held).
  void insertKeyFrame(const KeyFramePtr& kf);
  // Sequential mode: processes every queued keyframe (and the global BA a loop triggers) in the
  // caller's thread; does nothing in Threaded mode. The caller must NOT hold map.update_mutex.
  void processQueued();
  // Blocks until the queue is empty, no keyframe is processed and no global BA runs
  // (Sequential: returns at once, nothing runs in the background).
  void waitIdle();
  // Forgets queued keyframes and the consistency groups (map reset; thread stopped).
  void clear();

  // One keyframe's detection + verification + correction, synchronous (the thread and
  // processQueued() call this; tests may call it with the thread not started). Returns true if
  // a loop was closed.
  bool processOne(const KeyFramePtr& kf);

  size_t loopsClosed() const;
  size_t globalBundleAdjustments() const;   // completed and written back
  // (current keyframe id, loop keyframe id) of every closed loop.
  std::vector<std::pair<long, long>> loops() const;

 private:
  struct ConsistentGroup {
    std::vector<long> kfs;   // a candidate with its covisibles
    int count = 0;
  };
  void run();
  // Pops the front keyframe and processes it (lk holds queue_mutex_ on entry and on return,
  // released while processing).
  void processFront(std::unique_lock<std::mutex>& lk);
  struct Neighbourhood;
  using Links = std::vector<std::pair<long, long>>;   // (keyframe id, keyframe id)

  // Detection and verification: the caller holds update_mutex.
  std::vector<KeyFramePtr> detectLoop(const KeyFramePtr& kf);
  // The candidates whose covisibility group continues a consistent group (updates groups_).
  std::vector<KeyFramePtr> consistentCandidates(const std::vector<KeyFramePtr>& cands);
  // Verification of the candidates in turn; the first that passes is kept in matched_kf_,
  // T_cw_corrected_, current_matches_ and loop_points_.
  bool computeSE3(const KeyFramePtr& kf, const std::vector<KeyFramePtr>& cands);
  bool verifyCandidate(const KeyFramePtr& kf, const KeyFramePtr& cand, const std::vector<uint8_t>& use1,
                       std::mt19937& rng);
  // False (and a message) when the correction of T_cw against kf's pose exceeds the drift bound.
  bool withinDriftBound(const KeyFrame& kf, const KeyFrame& cand, const Pose& T_cw, double& corr_m,
                        double& corr_deg) const;

  // Correction: takes update_mutex (never while pausing LocalMapping); its steps 1-5 below run
  // with it held.
  void correctLoop(const KeyFramePtr& kf);
  // 1. Moves the current keyframe's neighbourhood (and the points it sees) rigidly with it.
  Neighbourhood moveNeighbourhood(const KeyFramePtr& kf);
  // 2. Fuses the verified matches (the current keyframe's points become the loop side's), then
  //    the loop side's points into the whole corrected neighbourhood.
  void fuseCurrentMatches(const KeyFramePtr& kf);
  void fuseLoopPoints(const std::vector<KeyFramePtr>& neighbourhood);
  // 3. Adds the loop edge; returns the new covisibility links the fusion created (the loop
  //    edges of the essential graph).
  Links linkLoop(const KeyFramePtr& kf, const KeyFramePtr& loop_kf, const Neighbourhood& n);
  // 4. Essential graph (spanning tree, loop edges, strong covisibility, new links) optimised
  //    from T_wc_start (the corrected poses); returns the optimised T_wc per keyframe.
  std::vector<optimization::PoseGraphEdge> essentialGraphEdges(
      const KeyFramePtr& kf, const KeyFramePtr& loop_kf, const std::vector<KeyFramePtr>& kfs,
      const std::map<long, Pose>& T_wc, const std::map<long, Pose>& T_wc_meas, const Links& new_links) const;
  std::map<long, Pose> optimizeEssentialGraph(const KeyFramePtr& kf, const KeyFramePtr& loop_kf,
                                              const std::vector<KeyFramePtr>& kfs,
                                              const std::map<long, Pose>& T_wc_start, const Neighbourhood& n,
                                              const Links& new_links);
  // 5. Writes the optimised poses back, and moves every point with its correcting keyframe.
  void writeBackCorrection(const std::vector<KeyFramePtr>& kfs, const std::map<long, Pose>& T_wc_start,
                           const std::map<long, Pose>& T_wc,
                           const std::unordered_map<long, long>& corrected_by);

  // Pauses LocalMapping and waits until it is paused; caller must NOT hold update_mutex.
  void pauseMapping();
  // Global BA: started with no lock held (Sequential: runs it to the end); runGlobalBA takes
  // update_mutex for the copy and the write-back, inside which the three helpers below run.
  void startGlobalBA(long loop_kf_id);
  void stopGlobalBA();
  void runGlobalBA(long loop_kf_id);
  optimization::BaProblem globalProblem() const;
  // Returns the correction T_wc_new * T_cw_old per keyframe written.
  std::unordered_map<long, Pose> writeBackKeyFrames(const optimization::BaProblem& problem);
  void writeBackPoints(const optimization::BaProblem& problem, const std::unordered_map<long, Pose>& corr);

  Map& map_;
  CameraModel cam_;
  LoopClosingOptions opt_;
  LocalMapping* mapper_;
  const RunMode mode_;

  mutable std::mutex queue_mutex_;
  std::condition_variable cv_;
  std::deque<KeyFramePtr> queue_;
  bool busy_ = false;
  bool stop_ = false;
  bool running_ = false;   // start() .. stop()
  size_t loops_closed_ = 0, gba_done_ = 0;
  std::vector<std::pair<long, long>> loops_;
  std::thread thread_;

  // Global BA thread (Threaded mode only): started by the loop thread only, joined by it
  // (before a new correction) or by stop(). gba_running_ is read by waitIdle.
  std::thread gba_thread_;
  std::atomic<bool> gba_stop_{false};
  std::atomic<bool> gba_running_{false};

  // Loop-thread state (only touched by the thread running processOne: the loop thread, or in
  // Sequential mode the caller of processQueued).
  std::vector<ConsistentGroup> groups_;
  long last_loop_kf_id_ = -1;
  KeyFramePtr matched_kf_;
  Pose T_cw_corrected_ = Pose::Identity();
  std::vector<MapPointPtr> current_matches_;   // per keypoint of the current kf: loop-side point
  std::vector<MapPointPtr> loop_points_;       // points of the loop keyframe and its covisibles
};

}  // namespace slam
}  // namespace yolo_slam
