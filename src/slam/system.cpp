#include "yolo_slam/slam/system.h"

#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/json.h"
#include "yolo_slam/common/log.h"
#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/local_mapping.h"
#include "yolo_slam/slam/loop_closing.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/slam/tracking.h"
#include "yolo_slam/vocabulary/keyframe_database.h"


#include <cmath>
#include <cstdio>
#include <unordered_map>

namespace yolo_slam {
namespace slam {

namespace {

// Initialisation needs Tracking.initMinKeyPoints static keypoints; a budget that cannot give them
// would lose every frame without a word.
void checkInitialisable(const SystemOptions& o, const std::string& where) {
  const double most = o.orb.n_features * o.orb.dynamic_boost_max;
  if (most < o.slam.tracking.init_min_keypoints)
    rejectOption(where, "ORBextractor.nFeatures",
                 ">= Tracking.initMinKeyPoints / ORBextractor.dynamicBoostMax = " +
                     formatNumber(o.slam.tracking.init_min_keypoints / o.orb.dynamic_boost_max) +
                     ", or tracking can never initialise (raise nFeatures or lower Tracking.initMinKeyPoints)",
                 std::to_string(o.orb.n_features));
}

}  // namespace

SystemOptions SystemOptions::load(const Config& cfg) {
  SystemOptions o;
  o.orb = features::OrbOptions::load(cfg);
  o.screening = screening::ScreeningOptions::load(cfg);
  o.slam = SlamOptions::load(cfg);
  o.dense = mapping::DenseMapOptions::load(cfg);
  o.sequential = cfg.getBool("System.sequential", o.sequential);
  o.young_map_sync = cfg.getBool("System.youngMapSync", o.young_map_sync);
  checkInitialisable(o, configName(cfg));
  return o;
}

System::System(const CameraModel& cam, const Config& cfg,
               std::shared_ptr<const vocabulary::Vocabulary> vocabulary)
    : System(cam, SystemOptions::load(cfg), std::move(vocabulary)) {}

System::System(const CameraModel& cam, const SystemOptions& options,
               std::shared_ptr<const vocabulary::Vocabulary> vocabulary)
    : cam_(cam),
      opt_(options.slam),
      run_mode_(options.sequential ? RunMode::Sequential : RunMode::Threaded),
      young_map_sync_(options.young_map_sync),
      orb_options_(options.orb),
      screening_options_(options.screening),
      voc_(std::move(vocabulary)) {
  const features::OrbOptions& orb_opt = options.orb;
  // Checked here, not at the first frame: the front end is made lazily.
  orb_opt.validate();
  screening_options_.validate("Screening");
  auto pyr = std::make_shared<ScalePyramid>(ScalePyramid::make(orb_opt.n_levels, orb_opt.scale_factor));
  map_ = std::make_unique<Map>();
  if (voc_) {
    kfdb_ = std::make_unique<vocabulary::KeyFrameDatabase>();
    map_->setKeyFrameDatabase(kfdb_.get());
  }
  mapper_ = std::make_unique<LocalMapping>(*map_, cam_, opt_.mapping, voc_, run_mode_);
  if (voc_ && opt_.loop.enabled) {
    loop_closer_ = std::make_unique<LoopClosing>(*map_, cam_, opt_.loop, mapper_.get(), run_mode_);
    mapper_->setLoopClosing(loop_closer_.get());
  }
  tracker_ = std::make_unique<Tracking>(cam_, opt_.tracking, *map_, mapper_.get(), voc_, pyr);
  if (options.dense.enabled) {
    // Poses change when a loop is closed or a global BA is written back.
    auto version = [this] {
      return loop_closer_ ? static_cast<long>(loop_closer_->loopsClosed() + loop_closer_->globalBundleAdjustments()) : 0L;
    };
    dense_ = std::make_unique<mapping::DenseMapper>(cam_, options.dense, screening_options_,
                                                    run_mode_ == RunMode::Threaded, version);
  }
  mapper_->start();
  if (loop_closer_) loop_closer_->start();
  if (dense_) dense_->start();
}

System::~System() { shutdown(); }

void System::shutdown() {
  std::lock_guard<std::mutex> lk(track_mutex_);
  if (shut_down_) return;
  shut_down_ = true;
  // Loop closing first: a correction or global BA in progress pauses the mapper and needs it.
  // As ORB-SLAM2's Shutdown, a pending loop and a running global BA are finished, not dropped
  // (a loop closed at the end of a sequence is otherwise left with only the pose-graph result).
  if (loop_closer_) {
    mapper_->waitIdle();
    loop_closer_->waitIdle();
    loop_closer_->stop();
  }
  mapper_->stop();
  if (dense_) dense_->stop();
}

namespace {
// System's policy for a depth image that does not fit: warn and track without depth.
cv::Mat usableDepth(const cv::Mat& depth, const cv::Mat& image, double stamp) {
  if (depth.empty() || image.empty()) return cv::Mat();
  if (depth.type() != CV_32FC1) {
    log::warn("frame %.6f: depth image of type %s, need CV_32FC1 metres (decode it "
                 "with io::decodeDepth); frame tracked without depth", stamp, cv::typeToString(depth.type()).c_str());
    return cv::Mat();
  }
  if (depth.size() != image.size()) {
    log::warn("frame %.6f: the depth image is %dx%d, the colour image %dx%d; "
                 "register the depth to the colour camera at its size; frame tracked without depth",
                 stamp, depth.cols, depth.rows, image.cols, image.rows);
    return cv::Mat();
  }
  return depth;
}

// An image of another size than the calibration would be tracked with the wrong intrinsics: a
// plausible but wrong trajectory. Refused loudly instead.
void checkImageSize(const cv::Mat& image, const CameraModel& cam, double stamp) {
  if (image.empty() || (image.cols == cam.width && image.rows == cam.height)) return;
  throw Error("frame " + formatNumber(stamp) + ": the colour image is " + std::to_string(image.cols) + "x" +
              std::to_string(image.rows) + " but the settings' Camera.width/height are " +
              std::to_string(cam.width) + "x" + std::to_string(cam.height) +
              "; use the settings file calibrated for this camera and image size (Camera.width, "
              "Camera.height, fx, fy, cx, cy)");
}
}  // namespace

namespace {
// The front end names the frame in most of its errors; the others get it here.
std::string namingTheFrame(const std::string& error, double stamp) {
  if (error.rfind("frame ", 0) == 0) return error;
  return "frame " + formatNumber(stamp) + ": " + error;
}
}  // namespace

frontend::FrontEnd& System::frontEnd() {
  std::call_once(front_end_once_, [this] {
    front_end_ = std::make_unique<frontend::FrontEnd>(orb_options_, screening_options_);
  });
  return *front_end_;
}

ExtractedFrame System::extractFrame(const cv::Mat& image, const cv::Mat& depth_m, double stamp) {
  checkImageSize(image, cam_, stamp);
  ExtractedFrame ef;
  ef.stamp = stamp;
  ef.image = image;
  ef.depth_m = usableDepth(depth_m, image, stamp);
  try {
    ef.extracted = frontEnd().extract(image, ef.depth_m, stamp, cam_);
  } catch (const Error& e) {
    ef.error = namingTheFrame(e.what(), stamp);
  }
  return ef;
}

TrackResult System::trackRgbd(const cv::Mat& image, const cv::Mat& depth_m, double stamp,
                              const detection::Boxes& boxes, bool detector_ran) {
  return trackExtracted(extractFrame(image, depth_m, stamp), boxes, detector_ran);
}

TrackResult System::trackExtracted(ExtractedFrame ef, const detection::Boxes& boxes, bool detector_ran) {
  frontend::FrontEndResult fe;
  if (ef.error.empty()) {
    try {
      fe = frontEnd().screen(std::move(ef.extracted), boxes, cam_, detector_ran);
    } catch (const Error& e) {
      ef.error = namingTheFrame(e.what(), ef.stamp);
    }
  }
  if (!ef.error.empty()) {
    log::warn("%s; frame reported lost", ef.error.c_str());
    fe = frontend::FrontEndResult();
    fe.frame.stamp = ef.stamp;
  }
  BoxCounts box_counts;
  for (const auto& b : fe.boxes) ++(b.tracked ? box_counts.tracked : box_counts.detected);
  {
    std::lock_guard<std::mutex> lk(stats_mutex_);
    stats_.extraction_ms.push_back(fe.stats.extraction_ms);
    stats_.screening_ms.push_back(fe.stats.screening_ms);
    stats_.keypoints += fe.stats.screening;
    stats_.temporal += fe.stats.temporal;
    stats_.boxes += box_counts;
    stats_.feature_budget_sum += fe.stats.feature_budget;
  }
  {
    std::lock_guard<std::mutex> lk(last_frame_mutex_);
    last_frame_ = fe.frame;
    last_boxes_ = fe.boxes;
  }
  // A map started on a frame screened without boxes would be built on the people in view, and
  // tracking would hold on to them (asynchronous detection, before its first result).
  if (fe.awaiting_detection && state() == TrackingState::NotInitialized) return skipAwaitingDetection();
  const TrackResult res = trackFeatures(fe.frame);
  addDenseKeyFrame(res, ef.image, ef.depth_m, fe.boxes);
  return res;
}

TrackResult System::skipAwaitingDetection() {
  std::lock_guard<std::mutex> lk(stats_mutex_);
  ++stats_.frames;
  ++stats_.lost;
  ++stats_.awaiting_detection;
  stats_.tracking_ms.push_back(0);  // keeps extraction_ms and tracking_ms frame by frame
  return TrackResult();
}

namespace {
// T_wc of a keyframe now: through the spanning tree when it was culled, nullopt when the
// keyframe is gone (map reset or replaced).
mapping::PoseGetter keyFramePose(const KeyFramePtr& kf, Map& map) {
  std::weak_ptr<KeyFrame> weak = kf;
  return [weak, &map]() -> std::optional<Pose> {
    const KeyFramePtr k = weak.lock();
    if (!k) return std::nullopt;
    std::lock_guard<std::mutex> ml(map.update_mutex);
    Pose T_kr;
    const KeyFramePtr live = liveAncestor(k, &T_kr);
    if (!live) return std::nullopt;
    return (T_kr * live->Tcw()).inverse();
  };
}
}  // namespace

void System::addDenseKeyFrame(const TrackResult& res, const cv::Mat& image, const cv::Mat& depth_m,
                              const detection::Boxes& boxes) {
  if (!dense_) return;
  if (res.keyframe_inserted && !depth_m.empty()) {
    mapping::DenseKeyFrame d;
    {
      std::lock_guard<std::mutex> tl(track_mutex_);
      std::lock_guard<std::mutex> ml(map_->update_mutex);
      const KeyFramePtr& kf = tracker_->lastKeyFrame();
      if (!kf) return;
      d.id = kf->id;
      d.stamp = kf->f.stamp;
      d.pose = keyFramePose(kf, *map_);
    }
    d.image = image.clone();
    d.depth_m = depth_m.clone();
    d.boxes = boxes;
    dense_->insert(std::move(d));
  }
  // Sequential: also after frames without a keyframe, so a loop's rebuild is not put off.
  if (run_mode_ == RunMode::Sequential) dense_->processQueued();
}

TrackResult System::trackFeatures(const features::FeatureFrame& frame) {
  std::lock_guard<std::mutex> tl(track_mutex_);
  TrackResult res;
  if (shut_down_) return res;
  Stopwatch sw;
  bool reset_requested = false;
  double lock_wait_ms = 0;
  {
    std::unique_lock<std::mutex> ml = map_->lockForTracking();
    lock_wait_ms = sw.ms();
    res = tracker_->track(frame);
    reset_requested = tracker_->resetRequested();
    if (res.state == TrackingState::Ok) markStaticAgain(frame.stamp, tracker_->lastDroppedMatched());
  }
  const double ms = sw.ms();
  if (res.state == TrackingState::Ok && !res.T_wc.matrix().allFinite()) res.state = TrackingState::Lost;
  {
    std::lock_guard<std::mutex> lk(stats_mutex_);
    stats_.tracking_ms.push_back(ms);
    stats_.map_lock_wait_ms.push_back(lock_wait_ms);
    ++stats_.frames;
    if (res.state == TrackingState::Ok) ++stats_.tracked;
    else ++stats_.lost;
  }
  if (reset_requested) {
    log::warn("frame %.6f: lost with a small or young map; map reset", frame.stamp);
    resetInternal(true);
  } else if (run_mode_ == RunMode::Sequential) {
    runBackEndInline();
  } else if (young_map_sync_ && res.keyframe_inserted && tracker_->mapIsYoung()) {
    mapper_->waitIdle();
  }
  return res;
}

void System::markStaticAgain(double stamp, const std::vector<int>& keypoints) {
  if (keypoints.empty()) return;
  std::lock_guard<std::mutex> lk(last_frame_mutex_);
  if (last_frame_.stamp != stamp) return;
  for (int i : keypoints) {
    if (i >= 0 && static_cast<size_t>(i) < last_frame_.dynamic.size()) last_frame_.dynamic[i] = 0;
  }
}

void System::runBackEndInline() {
  // Caller holds track_mutex_ (not update_mutex). Local mapping hands each processed keyframe
  // to loop closing, so its queue is complete once the mapper's is drained.
  mapper_->processQueued();
  if (loop_closer_) loop_closer_->processQueued();
}

void System::parkBackEnd() {
  if (loop_closer_) {
    loop_closer_->stop();
    loop_closer_->clear();
  }
  mapper_->pause();
  mapper_->waitUntilPaused();
  mapper_->clear();
}

void System::resumeBackEnd() {
  if (!localization_only_.load()) mapper_->resume();
  if (loop_closer_) loop_closer_->start();
}

void System::resetInternal(bool keep_trajectory) {
  // Caller holds track_mutex_. The back end is parked before the map is cleared.
  parkBackEnd();
  {
    std::lock_guard<std::mutex> ml(map_->update_mutex);
    Trajectory kfs;
    for (const auto& kf : map_->keyframes()) kfs.push_back({kf->f.stamp, kf->Twc()});
    if (keep_trajectory) {
      tracker_->freezeKeyFrames(kfs);
      tracker_->resetKeepTrajectory();
    } else {
      tracker_->resetAll();
    }
    map_->clear();
  }
  if (dense_) dense_->clear();
  {
    std::lock_guard<std::mutex> lk(stats_mutex_);
    ++stats_.resets;
  }
  resumeBackEnd();
}

MapFileContext System::mapFileContext() const {
  MapFileContext c;
  c.camera = cam_;
  c.orb_levels = orb_options_.n_levels;
  c.orb_scale_factor = orb_options_.scale_factor;
  c.vocabulary = voc_.get();
  return c;
}

MapFileInfo System::saveMap(const std::string& path) const {
  std::lock_guard<std::mutex> ml(map_->update_mutex);
  return saveMapFile(path, *map_, mapFileContext());
}

MapFileInfo System::loadMap(const std::string& path) {
  // Read and checked without any lock: the running map is not touched until this succeeded.
  auto loaded = std::make_unique<Map>();
  const MapFileInfo info = loadMapFile(path, mapFileContext(), *loaded);
  std::lock_guard<std::mutex> tl(track_mutex_);
  if (shut_down_) throw Error(path + ": cannot load a map into a System that was shut down");
  parkBackEnd();
  {
    std::lock_guard<std::mutex> ml(map_->update_mutex);
    tracker_->startInLoadedMap();
    map_->adopt(*loaded);
  }
  ++maps_loaded_;
  if (dense_) dense_->clear();
  resumeBackEnd();
  return info;
}

void System::reset() {
  std::lock_guard<std::mutex> tl(track_mutex_);
  if (shut_down_) return;
  resetInternal(false);
}

void System::setLocalizationOnly(bool on) {
  std::lock_guard<std::mutex> tl(track_mutex_);
  localization_only_.store(on);
  if (on) mapper_->pause();
  else mapper_->resume();
  std::lock_guard<std::mutex> ml(map_->update_mutex);
  tracker_->setLocalizationOnly(on);
}

bool System::localizationOnly() const { return localization_only_.load(); }

TrackingState System::state() const {
  std::lock_guard<std::mutex> tl(track_mutex_);
  return tracker_->state();
}

void System::waitForLocalMapping() { mapper_->waitIdle(); }

void System::waitForLoopClosing() {
  // Local mapping feeds loop closing, and a loop correction can hold up local mapping.
  mapper_->waitIdle();
  if (loop_closer_) loop_closer_->waitIdle();
  mapper_->waitIdle();
}

std::vector<std::pair<long, long>> System::loops() const {
  return loop_closer_ ? loop_closer_->loops() : std::vector<std::pair<long, long>>{};
}

features::FeatureFrame System::lastFrame() const {
  std::lock_guard<std::mutex> lk(last_frame_mutex_);
  return last_frame_;
}

detection::Boxes System::lastBoxes() const {
  std::lock_guard<std::mutex> lk(last_frame_mutex_);
  return last_boxes_;
}

void System::recordDetectionTime(double ms) {
  std::lock_guard<std::mutex> lk(stats_mutex_);
  stats_.detection_ms.push_back(ms);
}


Trajectory System::cameraTrajectory() const {
  std::lock_guard<std::mutex> tl(track_mutex_);
  std::lock_guard<std::mutex> ml(map_->update_mutex);
  return tracker_->trajectory();
}

Trajectory System::keyframeTrajectory() const {
  std::lock_guard<std::mutex> tl(track_mutex_);
  std::lock_guard<std::mutex> ml(map_->update_mutex);
  Trajectory out = tracker_->frozenKeyFrames();
  for (const auto& kf : map_->keyframes()) out.push_back({kf->f.stamp, kf->Twc()});
  return out;
}

MapSnapshot System::mapSnapshot() const {
  std::lock_guard<std::mutex> ml(map_->update_mutex);
  MapSnapshot s;
  for (const auto& mp : map_->mapPoints())
    if (!mp->dynamic && mp->Xw.allFinite()) s.points.push_back(mp->Xw);
  auto kfs = map_->keyframes();
  std::unordered_map<long, int> index;
  for (const auto& kf : kfs) {
    index[kf->id] = static_cast<int>(s.keyframes.size());
    s.keyframes.push_back({kf->f.stamp, kf->Twc()});
  }
  for (const auto& kf : kfs) {
    for (const auto& c : kf->connections) {
      if (c.first->id <= kf->id || c.second < kCovisibilityMinWeight) continue;
      auto it = index.find(c.first->id);
      if (it != index.end()) s.covisibility_edges.emplace_back(index[kf->id], it->second);
    }
  }
  return s;
}

LiveCounts System::liveCounts() const {
  LiveCounts c;
  {
    std::lock_guard<std::mutex> ml(map_->update_mutex);
    c.keyframes = map_->numKeyFrames();
    c.map_points = map_->numMapPoints();
  }
  c.local_mapping_median_ms = summarize(mapper_->timings()).median;
  // The frames of the last ten seconds at 30 Hz: what a monitor polling every second sees.
  constexpr size_t kRecentFrames = 300;
  std::lock_guard<std::mutex> lk(stats_mutex_);
  const std::vector<double>& waits = stats_.map_lock_wait_ms;
  const size_t from = waits.size() > kRecentFrames ? waits.size() - kRecentFrames : 0;
  for (size_t k = from; k < waits.size(); ++k) c.map_lock_wait_max_ms = std::max(c.map_lock_wait_max_ms, waits[k]);
  return c;
}

SystemStats System::stats() const {
  SystemStats s;
  {
    std::lock_guard<std::mutex> ml(map_->update_mutex);
    s.keyframes = map_->numKeyFrames();
    s.map_points = map_->numMapPoints();
  }
  LocalMappingTimings lm = mapper_->phaseTimings();
  size_t culled = mapper_->culledKeyFrames();
  size_t relocs = 0, jumps = 0, from_prediction = 0, young_dropped = 0, boxed_withheld = 0, dropped_matched = 0,
         vo_frames = 0, prior_mean_step = 0, relocs_refused = 0;
  {
    std::lock_guard<std::mutex> tl(track_mutex_);
    relocs = tracker_->relocalizations();
    jumps = tracker_->jumpsRefused();
    relocs_refused = tracker_->relocalizationsRefused();
    from_prediction = tracker_->trackedFromPrediction();
    young_dropped = tracker_->youngPointsDropped();
    prior_mean_step = tracker_->priorFromMeanStep();
    boxed_withheld = tracker_->boxedPointsWithheld();
    dropped_matched = tracker_->droppedMatched();
    vo_frames = tracker_->voFrames();
  }
  const size_t loops = loop_closer_ ? loop_closer_->loopsClosed() : 0;
  const size_t gbas = loop_closer_ ? loop_closer_->globalBundleAdjustments() : 0;
  std::lock_guard<std::mutex> lk(stats_mutex_);
  size_t kf = s.keyframes, mp = s.map_points;
  s = stats_;
  s.keyframes = kf;
  s.map_points = mp;
  s.local_mapping_ms = std::move(lm.total);
  s.lm_insert_ms = std::move(lm.insert);
  s.lm_fuse_ms = std::move(lm.fuse);
  s.lm_ba_ms = std::move(lm.ba);
  s.lm_culling_ms = std::move(lm.culling);
  s.keyframes_culled = culled;
  s.relocalizations = relocs;
  s.jumps_refused = jumps;
  s.relocalizations_refused = relocs_refused;
  s.tracked_from_prediction = from_prediction;
  s.young_points_dropped = young_dropped;
  s.prior_from_mean_step = prior_mean_step;
  s.boxed_points_withheld = boxed_withheld;
  s.dropped_map_matches = dropped_matched;
  s.vo_frames = vo_frames;
  s.loops_closed = loops;
  s.global_bas = gbas;
  return s;
}

size_t System::mapCorrections() const {
  size_t n = 0;
  {
    std::lock_guard<std::mutex> tl(track_mutex_);
    n += tracker_->relocalizations() + maps_loaded_;
  }
  if (loop_closer_) n += loop_closer_->loopsClosed() + loop_closer_->globalBundleAdjustments();
  std::lock_guard<std::mutex> lk(stats_mutex_);
  return n + stats_.resets;
}

BoxCounts& BoxCounts::operator+=(const BoxCounts& o) {
  detected += o.detected;
  tracked += o.tracked;
  return *this;
}

void to_json(Json& j, const BoxCounts& b) { j = Json{{"detected", b.detected}, {"tracked", b.tracked}}; }

Json statsCountsJson(const SystemStats& s) {
  return Json{{"frames", s.frames},
              {"tracked", s.tracked},
              {"lost", s.lost},
              {"keyframes", s.keyframes},
              {"keyframes_culled", s.keyframes_culled},
              {"map_points", s.map_points},
              {"map_resets", s.resets},
              {"relocalizations", s.relocalizations},
              {"jumps_refused", s.jumps_refused},
              {"relocalizations_refused", s.relocalizations_refused},
              {"tracked_from_prediction", s.tracked_from_prediction},
              {"young_points_dropped", s.young_points_dropped},
              {"prior_from_mean_step", s.prior_from_mean_step},
              {"boxed_points_withheld", s.boxed_points_withheld},
              {"dropped_map_matches", s.dropped_map_matches},
              {"vo_frames", s.vo_frames},
              {"loops_closed", s.loops_closed},
              {"global_bundle_adjustments", s.global_bas},
              {"awaiting_detection", s.awaiting_detection},
              {"keypoints", s.keypoints},
              {"temporal", s.temporal},
              {"boxes_screened", s.boxes},
              {"feature_budget_mean", jsonNumber(s.extraction_ms.empty() ? 0.0 : s.feature_budget_sum / s.extraction_ms.size())}};
}

std::vector<double> extractionPlusTrackingMs(const SystemStats& s) {
  std::vector<double> et;
  for (size_t k = 0; k < s.tracking_ms.size() && k < s.extraction_ms.size(); ++k)
    et.push_back(s.extraction_ms[k] + s.tracking_ms[k]);
  return et;
}

Json statsTimingsJson(const SystemStats& s,
                      const std::vector<std::pair<std::string, std::vector<double>>>& extra) {
  Json t{{"extraction", summaryJsonMs(summarize(s.extraction_ms))},
         {"screening", summaryJsonMs(summarize(s.screening_ms))},
         {"tracking", summaryJsonMs(summarize(s.tracking_ms))},
         {"extraction_plus_tracking", summaryJsonMs(summarize(extractionPlusTrackingMs(s)))},
         {"local_mapping", summaryJsonMs(summarize(s.local_mapping_ms))},
         {"detection", summaryJsonMs(summarize(s.detection_ms))},
         {"map_lock_wait", summaryJsonMs(summarize(s.map_lock_wait_ms))},
         {"local_mapping_insert", summaryJsonMs(summarize(s.lm_insert_ms))},
         {"local_mapping_fuse", summaryJsonMs(summarize(s.lm_fuse_ms))},
         {"local_mapping_ba", summaryJsonMs(summarize(s.lm_ba_ms))},
         {"local_mapping_culling", summaryJsonMs(summarize(s.lm_culling_ms))}};
  for (const auto& e : extra) t[e.first] = summaryJsonMs(summarize(e.second));
  return t;
}

std::string System::statsJson() const {
  const SystemStats s = stats();
  Json j = statsCountsJson(s);
  j["timings"] = statsTimingsJson(s);
  return dumpJson(j);
}

}  // namespace slam
}  // namespace yolo_slam
