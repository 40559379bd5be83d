#include "yolo_slam/detection/async_detector.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/common/thread_name.h"

#include <algorithm>

namespace yolo_slam {
namespace detection {

namespace {
// Results kept for newestUpTo: a frame offered as it arrives is at most a few frames ahead of the
// frame being screened, and one detection takes longer than a frame.
constexpr size_t kRecentResults = 4;
}  // namespace

AsyncDetectionOptions AsyncDetectionOptions::load(const Config& cfg) {
  AsyncDetectionOptions o;
  o.enabled = cfg.getBool("Detection.async", o.enabled);
  o.max_age_s = readDouble(cfg, "Detection.maxAge", o.max_age_s, Range::atLeast(0));
  o.threads = readInt(cfg, "Detection.asyncThreads", o.threads, Range::closed(1, DetectorOptions::kMaxThreads));
  o.min_interval_s = readDouble(cfg, "Detection.asyncMinInterval", o.min_interval_s, Range::atLeast(0));
  o.thread_nice = readInt(cfg, "Detection.threadNice", o.thread_nice, Range::closed(0, 19));
  o.max_lag_frames = readInt(cfg, "Detection.asyncMaxLag", o.max_lag_frames, Range::atLeast(0));
  return o;
}

AsyncDetector::AsyncDetector(std::unique_ptr<Detector> detector, double min_interval_s, int thread_nice)
    : detector_(std::move(detector)), min_interval_s_(min_interval_s) {
  if (!detector_) throw Error("AsyncDetector needs a detector");
  worker_ = std::thread([this, thread_nice] {
    nameThisThread("ys_detect");
    lowerThisThreadPriority(thread_nice, "Detection.threadNice");
    run();
  });
}

AsyncDetector::~AsyncDetector() {
  {
    std::lock_guard<std::mutex> lk(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  worker_.join();
}

void AsyncDetector::offer(const cv::Mat& bgr, long index, double stamp) {
  {
    std::lock_guard<std::mutex> lk(mutex_);
    ++counts_.offered;
    if (!admitLocked(stamp)) {
      ++counts_.throttled;
      return;
    }
    if (pending_) ++counts_.replaced;
    pending_ = Pending{bgr, index, stamp};
  }
  cv_.notify_all();
}

std::optional<DetectionResult> AsyncDetector::newest() const {
  std::lock_guard<std::mutex> lk(mutex_);
  if (recent_.empty()) return std::nullopt;
  return recent_.back();
}

std::optional<DetectionResult> AsyncDetector::newestUpTo(long index) const {
  std::lock_guard<std::mutex> lk(mutex_);
  const DetectionResult* best = nullptr;
  for (const DetectionResult& r : recent_)
    if (r.frame <= index && (!best || r.frame >= best->frame)) best = &r;
  if (!best) return std::nullopt;
  return *best;
}

void AsyncDetector::waitIdle() {
  std::unique_lock<std::mutex> lk(mutex_);
  cv_.wait(lk, [this] { return stop_ || (!pending_ && !busy_); });
}

bool AsyncDetector::waitForFrameIn(long first, long last, const cv::Mat& bgr, double stamp) {
  const auto in = [first, last](long frame) { return frame >= first && frame <= last; };
  std::unique_lock<std::mutex> lk(mutex_);
  const auto arrived = [&] {
    return std::any_of(recent_.begin(), recent_.end(), [&](const DetectionResult& r) { return in(r.frame); });
  };
  const auto coming = [&] { return (pending_ && in(pending_->index)) || (busy_ && in(busy_index_)); };
  // A newer frame offered meanwhile replaces the one offered again: offer it once more (the
  // caller's pipeline holds only a few frames ahead, so the offers end).
  while (!stop_ && !arrived()) {
    if (!coming()) {
      ++counts_.reoffered;
      if (pending_) ++counts_.replaced;
      pending_ = Pending{bgr, last, stamp};
      cv_.notify_all();
    }
    cv_.wait(lk, [&] { return stop_ || arrived() || !coming(); });
  }
  return arrived();
}

bool AsyncDetector::admitLocked(double stamp) const {
  // A stamp before the last taken one starts a new stream (a reset or another sequence).
  if (!last_taken_stamp_ || stamp < *last_taken_stamp_) return true;
  return stamp - *last_taken_stamp_ >= min_interval_s_;
}

AsyncDetectionCounts AsyncDetector::counts() const {
  std::lock_guard<std::mutex> lk(mutex_);
  return counts_;
}

void AsyncDetector::run() {
  std::unique_lock<std::mutex> lk(mutex_);
  for (;;) {
    cv_.wait(lk, [this] { return stop_ || pending_; });
    if (stop_) return;
    Pending job = std::move(*pending_);
    pending_.reset();
    last_taken_stamp_ = job.stamp;
    busy_ = true;
    busy_index_ = job.index;
    lk.unlock();
    DetectionResult r;
    r.frame = job.index;
    r.stamp = job.stamp;
    Stopwatch sw;
    try {
      r.boxes = detector_->detect(job.bgr);
    } catch (const std::exception& e) {
      r.error = e.what();
    }
    r.ms = sw.ms();
    lk.lock();
    busy_ = false;
    ++counts_.detected;
    recent_.push_back(std::move(r));
    if (recent_.size() > kRecentResults) recent_.pop_front();
    cv_.notify_all();
  }
}

FrameBoxes BoxFeed::take(const std::optional<DetectionResult>& newest, double frame_stamp) {
  FrameBoxes fb;
  if (!newest || newest->frame == last_used_) return fb;
  last_used_ = newest->frame;
  fb.age_s = frame_stamp - newest->stamp;
  fb.source_frame = newest->frame;
  if (fb.age_s > max_age_s_) {
    ++expired_;
    return fb;
  }
  fb.fresh = true;
  fb.boxes = newest->boxes;
  for (Box& b : fb.boxes) b.age_s = std::max(0.0, fb.age_s);
  return fb;
}

}  // namespace detection
}  // namespace yolo_slam
