#pragma once
// Detection that never holds up the frame stream (as NGD-SLAM and RDS-SLAM run YOLO): a worker
// thread detects people in the newest frame offered whenever it is free; a frame offered while
// another still waits replaces it (no backlog). Frames are offered as they arrive; a frame is
// screened with the newest finished result of its own or an earlier image, used only while it is
// recent (AsyncDetectionOptions::max_age_s); between results the screening's box tracker
// carries the boxes.
#include "yolo_slam/detection/box.h"
#include "yolo_slam/detection/detector.h"

#include <opencv2/core.hpp>

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

namespace yolo_slam {

class Config;

namespace detection {

struct AsyncDetectionOptions {
  // Detection.async: 1 detects asynchronously (the ROS launch files turn it on: a live camera
  // must never wait for the detector); 0 (default) detects every frame before it is screened:
  // the paper's pipeline, the most accurate (BENCHMARKS.md "Session 40": async at full speed
  // 0.97-1.11x its ATE on the walking presets) and, with --sequential, repeatable.
  bool enabled = false;
  // Detection.maxAge (seconds): a result is used for a frame at most this much younger than
  // the result's own frame. People walk about 1.4 m/s: in 0.2 s a box at 2 m is off by about a
  // tenth of its width, which the box dilation (Screening.boxDilation) and tracker absorb.
  double max_age_s = 0.2;
  // Detection.asyncThreads: the detector's threads when asynchronous (replaces Detector.threads).
  // One leaves the other core of a two-core machine to extraction, tracking and mapping; with
  // two, every detection takes both cores for its duration and the frame being tracked waits.
  int threads = 1;
  // Detection.asyncMinInterval (seconds of stream time): a frame is offered to the detector
  // only this long after the last frame it took. 0 detects whenever the detector is free; more
  // leaves CPU to the rest of the pipeline at the cost of carrying boxes over more frames.
  double min_interval_s = 0;
  // Detection.threadNice: the detection thread's nice value above the process's (asynchronous
  // detection: the offline runner's worker, the Detector nodelet's own thread), so that on a
  // busy CPU the frame stream goes first; the boxes then come less often.
  int thread_nice = 0;
  // Detection.asyncMaxLag (frames; yolo_slam_run at full speed only): a frame without a result
  // of an image at most this many frames older waits for one (AsyncDetector::waitForFrameIn
  // offers it again when the detector took a later frame). At full speed frames come faster than a
  // camera's and the detector sees one in three or four: people entering the view get their
  // boxes frames late. A camera (--camera-rate, --realtime, ROS) never waits: there the
  // detector keeps up. 0: never wait.
  int max_lag_frames = 3;
  static AsyncDetectionOptions load(const Config& cfg);  // throws Error naming file and key
};

struct DetectionResult {
  long frame = -1;     // the caller's index of the detected frame
  double stamp = 0;    // its stamp
  Boxes boxes;
  double ms = 0;       // detection time
  std::string error;   // the detector failed on this frame (boxes empty)
};

struct AsyncDetectionCounts {
  long offered = 0, detected = 0, replaced = 0;  // replaced: offered (or reoffered), never detected
  long throttled = 0;  // offered within min_interval_s of the last frame taken: not queued
  long reoffered = 0;  // offered again by waitForFrameIn (not in `offered`)
};

class AsyncDetector {
 public:
  explicit AsyncDetector(std::unique_ptr<Detector> detector, double min_interval_s = 0, int thread_nice = 0);
  ~AsyncDetector();  // finishes the frame in progress, then stops
  AsyncDetector(const AsyncDetector&) = delete;
  AsyncDetector& operator=(const AsyncDetector&) = delete;

  // Offers frame `index` (the image is shared, not copied: the caller must not write to it).
  void offer(const cv::Mat& bgr, long index, double stamp);
  // The newest finished result, if any.
  std::optional<DetectionResult> newest() const;
  // The newest finished result of frame `index` or earlier, if any: a frame offered as it
  // arrives may be detected before the frames ahead of it in the pipeline are screened.
  std::optional<DetectionResult> newestUpTo(long index) const;
  // Blocks until no frame waits and none is being detected (tests, end of a sequence).
  void waitIdle();
  // Blocks until a result of a frame in [first, last] is there; when none is there, waiting or
  // being detected (the detector took a later frame), `bgr`, frame `last`, is offered again
  // first. Returns whether such a result is there (false only when stopping).
  bool waitForFrameIn(long first, long last, const cv::Mat& bgr, double stamp);
  AsyncDetectionCounts counts() const;
  const Detector& detector() const { return *detector_; }

 private:
  void run();

  // Whether a frame of this stamp is queued (not within min_interval_s_ of the last taken one).
  bool admitLocked(double stamp) const;

  std::unique_ptr<Detector> detector_;  // used by the worker only
  const double min_interval_s_;
  // Guards everything below; taken alone. The worker releases it while it detects.
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  struct Pending {
    cv::Mat bgr;
    long index = -1;
    double stamp = 0;
  };
  std::optional<Pending> pending_;
  std::optional<double> last_taken_stamp_;  // stamp of the newest frame the worker took
  bool busy_ = false, stop_ = false;
  long busy_index_ = -1;  // the frame being detected while busy_
  // The last few results in the order they were made (frames increase, except for a frame
  // offered again by waitForFrameIn).
  std::deque<DetectionResult> recent_;
  AsyncDetectionCounts counts_;
  std::thread worker_;  // started last, in the constructor
};

// The boxes a frame is screened with, taken from the newest result of an AsyncDetector.
struct FrameBoxes {
  Boxes boxes;          // empty when no fresh result: the box tracker carries earlier boxes
  bool fresh = false;   // a result not used by an earlier frame
  long source_frame = -1;
  double age_s = 0;     // frame stamp - result stamp
};

// Per stream: hands each result to one frame only, and not when it is older than max_age_s.
class BoxFeed {
 public:
  explicit BoxFeed(double max_age_s) : max_age_s_(max_age_s) {}
  FrameBoxes take(const std::optional<DetectionResult>& newest, double frame_stamp);
  long expired() const { return expired_; }  // fresh results dropped for age

 private:
  double max_age_s_;
  long last_used_ = -1;
  long expired_ = 0;
};

}  // namespace detection
}  // namespace yolo_slam
