#include "yolo_slam/slam/tracking.h"

#include "yolo_slam/common/log.h"
#include "yolo_slam/optimization/pose_optimizer.h"
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/local_mapping.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/slam/matcher.h"
#include "yolo_slam/slam/observation.h"
#include "yolo_slam/slam/young_points.h"
#include "yolo_slam/vocabulary/keyframe_database.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

namespace yolo_slam {
namespace slam {

const char* toString(TrackingState s) {
  switch (s) {
    case TrackingState::NotInitialized: return "not_initialized";
    case TrackingState::Ok: return "ok";
    case TrackingState::Lost: return "lost";
  }
  return "?";
}

namespace {

// Matching thresholds of the tracking steps. Unless noted, ORB-SLAM2's values
// (Tracking::TrackWithMotionModel, TrackReferenceKeyFrame, Relocalization, UpdateLocalKeyFrames,
// SearchLocalPoints, NeedNewKeyFrame, CreateNewKeyFrame).
constexpr int kMinMotionMatches = 20;      // motion model: matches (else the window is doubled)
constexpr int kMinMapMatches = 10;         // motion model / reference keyframe: matches to map points
constexpr double kRefBowRatio = 0.7;       // reference keyframe: SearchByBoW nearest-neighbour ratio
constexpr int kMinBowMatches = 15;         // reference keyframe / relocalisation: SearchByBoW matches
// Reference keyframe without (enough) BoW matches: projection windows and the matches that end
// the widening (this project's choice; ORB-SLAM2 has no such fallback).
constexpr double kRefWindows[] = {5.0, 10.0};
constexpr int kRefWindowEnough = 20;
constexpr double kProjectionRatio = 0.9;   // projection searches against one keyframe
// Lost without relocalisation: the last reference keyframe's best covisibles tried, and the
// map matches one needs (this project's choice).
constexpr size_t kLostCovisibles = 10;
constexpr int kLostMinMapMatches = 30;
// Relocalisation: candidates tried (this project's cap on the cost of a lost frame), SearchByBoW
// ratio, PnP RANSAC (ORB-SLAM2 PnPsolver: 300 iterations, 0.99 confidence, 10 inliers; its chi2
// bound 5.991 serves as OpenCV's pixel error), inliers to accept (50), to retry with the narrow
// window (30), windows (10, 3).
constexpr size_t kMaxRelocCandidates = 20;
constexpr double kRelocBowRatio = 0.75;
constexpr int kPnpIterations = 300;
constexpr float kPnpReprojError = 5.991f;
constexpr double kPnpConfidence = 0.99;
constexpr int kPnpMinInliers = 10;
constexpr int kRelocMinInliers = 50;
constexpr int kRelocRetryMinInliers = 30;
constexpr double kRelocWindowWide = 10.0;
constexpr double kRelocWindowNarrow = 3.0;
// Local map: keyframes at most, covisibles per keyframe, minimum viewing cosine, NN ratio.
constexpr size_t kMaxLocalKeyFrames = 80;
constexpr size_t kLocalCovisibles = 10;
constexpr double kLocalViewCos = 0.5;
constexpr double kLocalRatio = 0.8;
// Keyframe decision: reference ratio with a map of one keyframe, share of the reference's points
// below which a keyframe is due anyway, and the inliers a keyframe needs.
constexpr double kRefRatioFirst = 0.4;
constexpr double kRefRatioLow = 0.25;
constexpr int kKeyFrameMinInliers = 15;

bool finitePose(const Pose& T) { return T.matrix().allFinite(); }

Pose poseFromRodrigues(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Pose T = Pose::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = R.at<double>(r, c);
    T.translation()(r) = tvec.at<double>(r);
  }
  return T;
}

// Releases the outlier associations of F (and clears their flags).
void releaseOutliers(Frame& F) {
  for (int i = 0; i < F.N; ++i)
    if (F.points[i] && F.outlier[i]) {
      F.points[i].reset();
      F.outlier[i] = false;
    }
}

// Drops F's associations to points erased or fused by local mapping.
void dropBadPoints(Frame& F) {
  for (auto& mp : F.points)
    if (mp && mp->bad) mp.reset();
}

void clearAssociations(Frame& F) {
  std::fill(F.points.begin(), F.points.end(), nullptr);
  std::fill(F.outlier.begin(), F.outlier.end(), false);
}

// The keyframes observing the frame's points, by id, each marked with the frame (KeyFrame::
// local_ref_frame) and counting the points it shares with it (local_count).
std::vector<const KeyFramePtr*> observingKeyFrames(const Frame& F) {
  std::vector<const KeyFramePtr*> seen;
  for (const auto& mp : F.points) {
    if (!mp) continue;
    for (const auto& o : mp->observations) {
      KeyFrame& kf = *o.first;
      if (kf.local_ref_frame != F.id) {
        kf.local_ref_frame = F.id;
        kf.local_count = 0;
        seen.push_back(&o.first);
      }
      ++kf.local_count;
    }
  }
  std::sort(seen.begin(), seen.end(),
            [](const KeyFramePtr* a, const KeyFramePtr* b) { return (*a)->id < (*b)->id; });
  return seen;
}

// Takes kf into the frame's local map unless it is bad or already in (marked with the frame).
bool takeIntoLocalMap(KeyFrame& kf, long frame_id) {
  if (kf.bad || kf.local_ref_frame == frame_id) return false;
  kf.local_ref_frame = frame_id;
  return true;
}

}  // namespace

Tracking::Tracking(const CameraModel& cam, const TrackingOptions& opt, Map& map, LocalMapping* mapper,
                   std::shared_ptr<const vocabulary::Vocabulary> vocabulary,
                   std::shared_ptr<const ScalePyramid> pyramid)
    : cam_(cam), opt_(opt), map_(map), mapper_(mapper), voc_(std::move(vocabulary)),
      pyr_(std::move(pyramid)), geom_(FrameGeometry::make(cam)) {
  max_frames_ = opt_.max_frames_between_kf > 0 ? opt_.max_frames_between_kf
                                               : std::max(1, static_cast<int>(std::lround(cam_.fps)));
  min_frames_ = opt_.min_frames_between_kf;
}

TrackResult Tracking::track(const features::FeatureFrame& ff) {
  reset_requested_ = false;
  ++frames_;
  dropped_matched_.clear();
  Frame F(ff, cam_, geom_, pyr_, next_frame_id_++);
  checkTimestamp(F);
  if (state_ == TrackingState::NotInitialized) return trackFirst(F);
  updateLastFrame();
  TrackResult res;
  if (trackFrame(F)) onTracked(F, res);
  else onFailed(res);
  return res;
}

void Tracking::checkTimestamp(const Frame& F) {
  // A timestamp that goes backwards or jumps invalidates the constant-velocity prediction.
  const bool stamp_ok = std::isfinite(F.stamp);
  if (stamp_ok && has_last_stamp_) {
    const double dt = F.stamp - last_stamp_;
    if (!(dt > 0) || dt > opt_.max_stamp_gap) {
      if (has_velocity_)
        log::warn("frame %.6f: timestamp jump of %.3f s; motion model reset",
                     F.stamp, dt);
      forgetMotion();
    }
  }
  if (stamp_ok) {
    last_stamp_ = F.stamp;
    has_last_stamp_ = true;
  }
}

TrackResult Tracking::trackFirst(Frame& F) {
  TrackResult res;
  if (!initialize(F)) {
    ++lost_;
    res.state = TrackingState::NotInitialized;
    return res;
  }
  state_ = TrackingState::Ok;
  res.inliers = F.countWithDepth();
  res.keyframe_inserted = true;
  acceptFrame(F, res);
  return res;
}

bool Tracking::trackFrame(Frame& F) {
  bool ok = false, from_prediction = false;
  const bool predicted = state_ == TrackingState::Ok && has_last_ && has_velocity_;
  const Pose prediction = predicted ? Pose(velocity_ * last_.T_cw) : Pose::Identity();
  // Right after a relocalisation the velocity measures the relocalised pose's correction, not the
  // camera's motion: a prior would hold on to it.
  if (predicted && opt_.motion_prior > 0 && !justRelocalized(F))
    prior_ = motionPrior(F, priorPrediction(prediction));
  if (state_ == TrackingState::Ok && has_last_) {
    if (has_velocity_) ok = trackMotionModel(F);
    if (!ok && ref_kf_ && !ref_kf_->bad)
      ok = trackReferenceKeyFrame(F, ref_kf_, last_.T_cw, kMinMapMatches);
    if (!ok && predicted && opt_.local_map_from_prediction) {
      startFromPrediction(F, prediction);
      ok = from_prediction = true;
    }
    // No velocity (the frame after a relocalisation or a lost stretch) and the reference
    // keyframe lost: place recognition now rather than a frame later, when the state turns Lost.
    if (!ok && !predicted) ok = relocalize(F);
  } else {
    ok = trackWhenLost(F);
  }
  if (ok) ok = trackLocalMap(F);
  prior_.reset();
  if (ok && predicted && implausibleJump(F.T_cw, prediction)) {
    ++jumps_refused_;
    ok = false;
  }
  ok = ok && finitePose(F.T_cw);
  if (ok && from_prediction) ++from_prediction_;
  return ok;
}

void Tracking::startFromPrediction(Frame& F, const Pose& prediction) const {
  clearAssociations(F);
  F.setPose(prediction);
}

optimization::PosePrior Tracking::motionPrior(const Frame& F, const Pose& prediction) const {
  // The prediction is one velocity step ahead of the last frame: after dropped frames it lags
  // by the missing steps, so the sigmas widen with the gap.
  double steps = 1.0;
  if (std::isfinite(F.stamp) && std::isfinite(last_.stamp) && cam_.fps > 0)
    steps = std::max(1.0, (F.stamp - last_.stamp) * cam_.fps);
  optimization::PosePrior p;
  p.T_cw = prediction;
  p.sigma_m = opt_.motion_prior * steps;
  p.sigma_rad = opt_.motion_prior_deg * M_PI / 180.0 * steps;
  return p;
}

Pose Tracking::priorPrediction(const Pose& prediction) {
  if (opt_.motion_prior_frames <= 1) return prediction;
  const PredictionTolerance tol{opt_.motion_prior, opt_.motion_prior_deg * M_PI / 180.0};
  const Pose p = robustPrediction(recent_, opt_.motion_prior_frames, prediction, last_.T_cw, tol);
  if (p.matrix() != prediction.matrix()) ++prior_mean_step_;
  return p;
}

void Tracking::forgetMotion() {
  has_velocity_ = false;
  recent_.clear();
}

bool Tracking::implausibleJump(const Pose& T_cw, const Pose& prediction) const {
  const double max_jump = localization_only_ ? opt_.max_jump_localization : opt_.max_jump;
  if (max_jump <= 0 || inliers_ >= opt_.max_jump_inliers) return false;
  const PoseGap gap = poseGap(T_cw, prediction);
  return gap.moved_m > max_jump || gap.turned_rad * 180.0 / M_PI > opt_.max_jump_deg;
}

void Tracking::onTracked(Frame& F, TrackResult& res) {
  const bool was_lost = state_ == TrackingState::Lost;
  failures_in_row_ = 0;
  lost_frames_in_row_ = 0;
  state_ = TrackingState::Ok;
  // After a lost stretch the last tracked frame is far in the past: no velocity from it.
  if (has_last_ && !was_lost) {
    velocity_ = F.T_cw * last_.T_cw.inverse();
    has_velocity_ = finitePose(velocity_);
  }
  if (!has_velocity_) recent_.clear();
  recent_.push(F.T_cw, static_cast<size_t>(opt_.motion_prior_frames) + 1);
  // Drop associations to temporary visual-odometry points.
  for (int i = 0; i < F.N; ++i) {
    if (F.points[i] && F.points[i]->numObservations() < 1) {
      F.points[i].reset();
      F.outlier[i] = false;
    }
  }
  temporary_points_.clear();
  if (!localization_only_ && needNewKeyFrame(F)) {
    createNewKeyFrame(F);
    res.keyframe_inserted = true;
  }
  // Outliers are not carried to the next frame (they stayed in the keyframe if one was made).
  for (int i = 0; i < F.N; ++i)
    if (F.points[i] && F.outlier[i]) F.points[i].reset();
  acceptFrame(F, res);
  res.inliers = inliers_;
}

void Tracking::onFailed(TrackResult& res) {
  temporary_points_.clear();
  ++lost_;
  ++failures_in_row_;
  ++lost_frames_in_row_;
  res.state = TrackingState::Lost;
  res.inliers = inliers_;
  // One bad frame (blur, a glitch) is skipped; two in a row mean lost (the velocity is
  // no longer trustworthy).
  if (failures_in_row_ >= 2 || state_ == TrackingState::Lost) {
    state_ = TrackingState::Lost;
    forgetMotion();
  }
  if (state_ == TrackingState::Lost && !localization_only_ && (lostLongInSmallMap() || lostYoung()))
    reset_requested_ = true;
}

bool Tracking::lostLongInSmallMap() const {
  return lost_frames_in_row_ >= opt_.lost_reset_frames &&
         static_cast<int>(map_.numKeyFrames()) <= opt_.lost_reset_max_keyframes;
}

bool Tracking::lostYoung() const {
  if (opt_.young_lost_reset_frames <= 0 || init_frame_id_ < 0 || last_tracked_id_ < 0) return false;
  return last_tracked_id_ - init_frame_id_ < opt_.young_map_frames &&
         lost_frames_in_row_ >= opt_.young_lost_reset_frames;
}

bool Tracking::mapIsYoung() const {
  return init_frame_id_ >= 0 && last_tracked_id_ >= init_frame_id_ &&
         last_tracked_id_ - init_frame_id_ < opt_.young_map_frames;
}

bool Tracking::youngMap(const Frame& F) const {
  return init_frame_id_ >= 0 && F.id - init_frame_id_ < opt_.young_map_frames;
}

void Tracking::acceptFrame(const Frame& F, TrackResult& res) {
  ++tracked_;
  last_tracked_id_ = F.id;
  res.state = TrackingState::Ok;
  res.T_wc = F.Twc();
  record(F);
  last_ = F;
  has_last_ = true;
  last_good_T_wc_ = F.Twc();
  has_last_good_ = true;
}

bool Tracking::initialize(Frame& F) {
  int n_static = 0;
  for (int i = 0; i < F.N; ++i) n_static += F.dynamic[i] ? 0 : 1;
  if (n_static < opt_.init_min_keypoints || F.countWithDepth() < opt_.init_min_depth_points) return false;
  F.setPose(has_last_good_ ? last_good_T_wc_.inverse() : Pose::Identity());
  auto kf = std::make_shared<KeyFrame>(map_.newKeyFrameId(), F);
  computeBow(voc_.get(), kf->f);
  map_.addKeyFrame(kf);
  for (int i = 0; i < F.N; ++i) {
    if (F.depth[i] <= 0 || F.dynamic[i]) continue;
    createDepthPoint(kf, F, i);
  }
  if (mapper_) mapper_->insertKeyFrame(kf);
  last_kf_ = kf;
  ref_kf_ = kf;
  last_kf_frame_id_ = F.id;
  init_frame_id_ = F.id;
  init_kf_id_ = kf->id;
  local_kfs_ = {kf};
  local_points_ = kf->mapPoints();
  forgetMotion();
  recent_.push(F.T_cw, static_cast<size_t>(opt_.motion_prior_frames) + 1);
  failures_in_row_ = 0;
  return true;
}

void Tracking::updateLastFrame() {
  if (!has_last_) return;
  // Points of the last frame may have been fused or culled by local mapping.
  for (auto& p : last_.points)
    if (p && p->bad) p = MapPoint::resolve(p);
  if (!last_ref_) return;
  // The reference keyframe may have been refined by local BA since.
  Pose T_rr = Pose::Identity();  // T_{ref_old, ref}
  const KeyFramePtr ref = liveAncestor(last_ref_, &T_rr);
  if (ref) last_.setPose(T_lr_ * T_rr * ref->Tcw());
  // ORB-SLAM2 creates temporary close points in the last frame only in localization mode,
  // where no keyframes (and so no new map points) are made.
  if (localization_only_ && last_kf_frame_id_ != last_.id) addTemporaryPoints();
}

void Tracking::addTemporaryPoints() {
  int map_points = 0;
  for (int i = 0; i < last_.N; ++i)
    if (last_.points[i] && last_.points[i]->numObservations() > 0) ++map_points;
  if (map_points >= opt_.vo_below_map_points) return;
  const size_t before = temporary_points_.size();
  addTemporaryCloseFirst();
  if (temporary_points_.size() > before) ++vo_frames_;
}

void Tracking::addTemporaryCloseFirst() {
  const std::vector<std::pair<float, int>> by_depth = last_.staticByDepth();
  int n = 0;
  for (const auto& e : by_depth) {
    const int i = e.second;
    const MapPointPtr& mp = last_.points[i];
    if (!mp || mp->numObservations() < 1) {
      if (last_.seenMoving(i)) continue;
      Eigen::Vector3d Xw;
      if (!last_.unprojectWorld(i, Xw)) continue;
      auto tmp = std::make_shared<MapPoint>(-1, Xw, nullptr, last_.id);
      tmp->descriptor = last_.descriptors.row(i).clone();
      const double d = (Xw - last_.cameraCenter()).norm();
      tmp->max_dist = d * pyr_->scale[last_.kps[i].octave];
      tmp->min_dist = tmp->max_dist / pyr_->scale[pyr_->n_levels - 1];
      tmp->normal = (Xw - last_.cameraCenter()).normalized();
      last_.points[i] = tmp;
      temporary_points_.push_back(tmp);
    }
    ++n;
    if (e.first > cam_.closeDepth() && n > opt_.vo_points) break;
  }
}

int Tracking::optimizePose(Frame& F) {
  std::vector<optimization::PoseObservation> obs;
  std::vector<int> idx;
  for (int i = 0; i < F.N; ++i) {
    const MapPointPtr& mp = F.points[i];
    if (!mp || F.dynamic[i]) continue;
    obs.push_back(poseObservation(F, i, mp->Xw));
    idx.push_back(i);
  }
  if (obs.size() < 3) return 0;
  std::vector<bool> is_outlier(obs.size(), false);
  Pose T = F.T_cw;
  int inl = optimization::optimizePose(cam_, T, obs, is_outlier, optimization::kPoseRounds, prior_ ? &*prior_ : nullptr);
  if (!finitePose(T)) return 0;
  F.setPose(T);
  for (size_t k = 0; k < idx.size(); ++k) F.outlier[idx[k]] = is_outlier[k];
  return inl;
}

bool Tracking::trackMotionModel(Frame& F) {
  F.setPose(velocity_ * last_.T_cw);
  std::fill(F.points.begin(), F.points.end(), nullptr);
  int n = matcher::searchLastFrame(F, last_, opt_.motion_window);
  if (n < kMinMotionMatches) {
    std::fill(F.points.begin(), F.points.end(), nullptr);
    n = matcher::searchLastFrame(F, last_, 2.0 * opt_.motion_window);
  }
  if (n < kMinMotionMatches) return false;
  const int n_map = optimizePoseAndDropOutliers(F);
  if (localization_only_) return n_map >= kMinMapMatches || n >= kMinMotionMatches;
  return n_map >= kMinMapMatches;
}

bool Tracking::createDepthPoint(const KeyFramePtr& kf, Frame& F, int i) {
  Eigen::Vector3d Xw;
  if (!F.unprojectWorld(i, Xw)) return false;
  auto mp = std::make_shared<MapPoint>(map_.newPointId(), Xw, kf.get(), F.id);
  Map::addObservation(mp, kf, i);
  mp->computeDistinctiveDescriptor();
  mp->updateNormalAndDepth();
  map_.addMapPoint(mp);
  F.points[i] = mp;
  F.outlier[i] = false;
  return true;
}

int Tracking::optimizePoseAndDropOutliers(Frame& F) {
  optimizePose(F);
  int n_map = 0;
  for (int i = 0; i < F.N; ++i) {
    if (!F.points[i]) continue;
    if (F.outlier[i]) {
      F.points[i]->last_seen_frame = F.id;
      F.points[i].reset();
      F.outlier[i] = false;
    } else if (F.points[i]->numObservations() > 0) {
      ++n_map;
    }
  }
  return n_map;
}

bool Tracking::trackReferenceKeyFrame(Frame& F, const KeyFramePtr& kf, const Pose& prior,
                                      int min_inliers) {
  clearAssociations(F);
  F.setPose(prior);
  int n = 0;
  if (voc_) {
    computeBow(voc_.get(), F);
    computeBow(voc_.get(), kf->f);
    n = matcher::searchByBow(*kf, F, kRefBowRatio);
  }
  if (n < kMinBowMatches) {
    // Without BoW (or when it finds too little): projection of the keyframe's points with the
    // prior pose, widening the window once.
    for (double th : kRefWindows) {
      std::fill(F.points.begin(), F.points.end(), nullptr);
      n = searchKeyFramePoints(F, *kf, th);
      if (n >= kRefWindowEnough) break;
    }
  }
  if (n < kMinBowMatches) return false;
  const int n_map = optimizePoseAndDropOutliers(F);
  return n_map >= min_inliers;
}

int Tracking::searchKeyFramePoints(Frame& F, const KeyFrame& kf, double th) const {
  std::set<long> have;
  for (const auto& mp : F.points)
    if (mp) have.insert(mp->id);
  std::vector<matcher::Projection> proj;
  for (const auto& mp : kf.mapPoints()) {
    if (mp->dynamic || have.count(mp->id)) continue;
    matcher::Projection p;
    if (matcher::projectInFrame(F, mp, 0.0, p)) proj.push_back(p);
  }
  return matcher::searchProjections(F, proj, th, kProjectionRatio);
}

bool Tracking::trackWhenLost(Frame& F) {
  // Place recognition over the whole map first (needs a vocabulary); then, for runs without
  // one, the last reference keyframe and its covisibles with the last good pose as prior.
  if (relocalize(F)) return true;
  if (!has_last_good_) return false;
  std::vector<KeyFramePtr> cands;
  const KeyFramePtr ref = liveAncestor(ref_kf_);
  if (ref) {
    cands.push_back(ref);
    for (const auto& k : ref->bestCovisibles(kLostCovisibles)) cands.push_back(k);
  }
  const Pose prior = last_good_T_wc_.inverse();
  for (const auto& kf : cands) {
    if (kf->bad) continue;
    if (trackReferenceKeyFrame(F, kf, prior, kLostMinMapMatches)) {
      if (refusedAsUnreachable(F)) continue;
      ref_kf_ = kf;
      return true;
    }
    // The camera moved on while people hid the room (lost for tens of frames: tens of
    // centimetres, degrees): the last good pose is too far for the optimisation to start from,
    // so the pose comes from PnP on the keyframe's matches, as a relocalisation near the place
    // where tracking was lost, which also needs fewer inliers than one over the whole map.
    if (relocalizeOn(F, kf, kLostMinMapMatches)) {
      if (refusedAsUnreachable(F)) continue;
      acceptRelocalization(F, kf);
      return true;
    }
  }
  return false;
}

bool Tracking::relocalize(Frame& F) {
  vocabulary::KeyFrameDatabase* db = map_.keyFrameDatabase();
  if (!voc_ || !db || F.N == 0) return false;
  computeBow(voc_.get(), F);
  if (F.bow.empty()) return false;

  // Candidates (ORB-SLAM2 DetectRelocalizationCandidates): keyframes sharing enough words, then
  // grouped with their 10 best covisibles; groups scoring > 0.75 x the best group survive, each
  // represented by its best keyframe.
  const auto hits = db->query(F.bow.bow, 0);
  if (hits.empty()) return false;
  std::vector<KeyFramePtr> cands = covisibilityGroupCandidates(map_, hits);
  if (cands.size() > kMaxRelocCandidates) cands.resize(kMaxRelocCandidates);
  for (const KeyFramePtr& kf : cands) {
    if (!relocalizeOn(F, kf, kRelocMinInliers)) continue;
    if (refusedAsUnreachable(F)) continue;
    acceptRelocalization(F, kf);
    return true;
  }
  clearAssociations(F);
  return false;
}

// TrackingOptions::reloc_max_speed: the pose F holds, found while lost, lies farther from the last
// good pose than the camera can have moved since the last tracked frame; a refusal is counted.
bool Tracking::refusedAsUnreachable(const Frame& F) {
  if (opt_.reloc_max_speed <= 0 || !has_last_good_ || !has_last_) return false;
  // Time going backwards (a bag played again) says nothing of how far the camera went.
  const double dt = F.stamp - last_.stamp;
  if (!std::isfinite(dt) || dt < 0) return false;
  const double moved = (F.Twc().translation() - last_good_T_wc_.translation()).norm();
  if (moved <= opt_.reloc_max_speed * dt + opt_.reloc_margin) return false;
  ++relocalizations_refused_;
  return true;
}

void Tracking::acceptRelocalization(const Frame& F, const KeyFramePtr& kf) {
  ref_kf_ = kf;
  last_reloc_frame_id_ = F.id;
  forgetMotion();
  ++relocalizations_;
}

bool Tracking::relocalizeOn(Frame& F, const KeyFramePtr& kf, int min_inliers) {
  computeBow(voc_.get(), kf->f);
  clearAssociations(F);
  if (matcher::searchByBow(*kf, F, kRelocBowRatio) < kMinBowMatches) return false;
  if (!pnpPose(F)) return false;
  int good = optimizePose(F);
  if (good < kPnpMinInliers) return false;
  releaseOutliers(F);
  // Few inliers: look for more by projecting the candidate's points (ORB-SLAM2 window 10,
  // then 3 with the refined pose).
  if (good < min_inliers && searchKeyFramePoints(F, *kf, kRelocWindowWide) + good >= min_inliers) {
    good = optimizePose(F);
    if (good > kRelocRetryMinInliers && good < min_inliers) {
      for (int i = 0; i < F.N; ++i)
        if (F.points[i] && F.outlier[i]) F.points[i].reset();
      if (searchKeyFramePoints(F, *kf, kRelocWindowNarrow) + good >= min_inliers) good = optimizePose(F);
    }
  }
  if (good < min_inliers) return false;
  releaseOutliers(F);
  return true;
}

bool Tracking::pnpPose(Frame& F) const {
  // PnP RANSAC on the BoW matches (undistorted keypoints: no distortion coefficients).
  std::vector<cv::Point3f> obj;
  std::vector<cv::Point2f> img;
  std::vector<int> idx;
  for (int i = 0; i < F.N; ++i) {
    const MapPointPtr& mp = F.points[i];
    if (!mp || mp->bad) continue;
    obj.emplace_back(static_cast<float>(mp->Xw.x()), static_cast<float>(mp->Xw.y()),
                     static_cast<float>(mp->Xw.z()));
    img.push_back(F.kps[i].pt);
    idx.push_back(i);
  }
  if (static_cast<int>(obj.size()) < kMinBowMatches) return false;
  const cv::Mat K = (cv::Mat_<double>(3, 3) << cam_.fx, 0, cam_.cx, 0, cam_.fy, cam_.cy, 0, 0, 1);
  cv::Mat rvec, tvec;
  std::vector<int> inl;
  bool ok = false;
  try {
    ok = cv::solvePnPRansac(obj, img, K, cv::noArray(), rvec, tvec, false, kPnpIterations, kPnpReprojError,
                            kPnpConfidence, inl, cv::SOLVEPNP_EPNP);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok || static_cast<int>(inl.size()) < kPnpMinInliers) return false;
  const Pose T = poseFromRodrigues(rvec, tvec);
  if (!finitePose(T)) return false;
  std::vector<bool> keep(F.N, false);
  for (int k : inl) keep[idx[k]] = true;
  for (int i = 0; i < F.N; ++i)
    if (!keep[i]) F.points[i].reset();
  F.setPose(T);
  return true;
}

void Tracking::updateLocalMap(Frame& F) {
  // Local keyframes: those sharing points with the frame, plus their best covisibles,
  // a child and the parent (ORB-SLAM2 UpdateLocalKeyFrames).
  dropBadPoints(F);
  const std::vector<const KeyFramePtr*> observing = observingKeyFrames(F);
  // Without associations (startFromPrediction) the last frame's local map stays.
  if (observing.empty()) return;
  local_kfs_.clear();
  int max_count = 0;
  KeyFramePtr best;
  for (const KeyFramePtr* kf : observing) {
    if ((*kf)->bad) continue;
    if ((*kf)->local_count > max_count) {
      max_count = (*kf)->local_count;
      best = *kf;
    }
    local_kfs_.push_back(*kf);
  }
  const size_t n_direct = local_kfs_.size();
  for (size_t k = 0; k < n_direct && local_kfs_.size() < kMaxLocalKeyFrames; ++k) {
    KeyFramePtr kf = local_kfs_[k];
    for (const auto& nb : kf->bestCovisibles(kLocalCovisibles)) {
      if (takeIntoLocalMap(*nb, F.id)) {
        local_kfs_.push_back(nb);
        break;
      }
    }
    for (KeyFrame* child : kf->children) {
      if (takeIntoLocalMap(*child, F.id)) {
        local_kfs_.push_back(child->self());
        break;
      }
    }
    if (kf->parent && takeIntoLocalMap(*kf->parent, F.id)) local_kfs_.push_back(kf->parent);
  }
  if (best) ref_kf_ = best;

  local_points_.clear();
  for (const auto& kf : local_kfs_) {
    for (const auto& mp : kf->f.points) {
      if (!mp || mp->bad || mp->dynamic || mp->local_ref_frame == F.id) continue;
      mp->local_ref_frame = F.id;
      local_points_.push_back(mp);
    }
  }
}

void Tracking::searchLocalPoints(Frame& F) {
  dropBadPoints(F);
  for (const auto& mp : F.points) {
    if (!mp) continue;
    mp->visible++;
    mp->last_seen_frame = F.id;
  }
  std::vector<matcher::Projection> proj;
  for (const auto& mp : local_points_) {
    if (mp->last_seen_frame == F.id || mp->bad) continue;
    matcher::Projection p;
    if (matcher::projectInFrame(F, mp, kLocalViewCos, p)) {
      mp->visible++;
      proj.push_back(p);
    }
  }
  if (proj.empty()) return;
  dynamic_hits_.clear();
  matcher::DroppedMatching dropped;
  // Only in a map this run does not change: in SLAM mode the matches measured no better.
  dropped.min_observations = localization_only_ ? opt_.dropped_map_matches : 0;
  dropped.matched = &dropped_matched_;
  matcher::searchProjections(F, proj, opt_.local_window, kLocalRatio, &dynamic_hits_, &dropped);
}

void Tracking::settleDroppedMatches(Frame& F) {
  size_t kept = 0;
  for (int j : dropped_matched_) {
    if (F.points[j]) {
      dropped_matched_[kept++] = j;
    } else {
      F.dynamic[j] = 1;
    }
  }
  dropped_matched_.resize(kept);
}

bool Tracking::trackLocalMap(Frame& F) {
  updateLocalMap(F);
  searchLocalPoints(F);
  optimizePose(F);
  if (opt_.young_point_check && dropDisagreeingYoungPoints(F) > 0) optimizePose(F);
  inliers_ = 0;
  for (int i = 0; i < F.N; ++i) {
    const MapPointPtr& mp = F.points[i];
    if (!mp) continue;
    if (!F.outlier[i]) {
      mp->found++;
      if (localization_only_ || mp->numObservations() > 0) ++inliers_;
    } else {
      // RGB-D: outliers are dropped right away (ORB-SLAM2 does so for stereo).
      F.points[i].reset();
    }
  }
  settleDroppedMatches(F);
  const bool ok = inliers_ >= minInliers(F);
  if (ok) dropped_matched_total_ += dropped_matched_.size();
  return ok;
}

bool Tracking::justRelocalized(const Frame& F) const {
  return last_reloc_frame_id_ >= 0 && F.id < last_reloc_frame_id_ + max_frames_;
}

int Tracking::minInliers(const Frame& F) const {
  return justRelocalized(F) ? std::max(opt_.min_inliers, opt_.reloc_min_inliers) : opt_.min_inliers;
}

int Tracking::dropDisagreeingYoungPoints(Frame& F) {
  const long last_kf_id = last_kf_ ? last_kf_->id : -1;
  const int released = releaseDisagreeingYoung(
      cam_, F, [&](const MapPoint& mp) { return isYoung(mp, last_kf_id, init_kf_id_); }, prior_ ? &*prior_ : nullptr);
  young_dropped_ += released;
  return released;
}

bool Tracking::needNewKeyFrame(const Frame& F) const {
  if (!mapper_ || mapper_->paused()) return false;
  const int n_kfs = static_cast<int>(map_.numKeyFrames());
  // Right after a relocalisation the pose rests on few points: wait (ORB-SLAM2).
  if (justRelocalized(F) && n_kfs > max_frames_) return false;
  const int min_obs = n_kfs <= 2 ? 2 : 3;
  KeyFramePtr ref = ref_kf_;
  const int ref_matches = ref && !ref->bad ? ref->trackedMapPoints(min_obs) : 0;
  const bool idle = mapper_->acceptsKeyFrames();
  int tracked_close = 0, untracked_close = 0;
  const double close = cam_.closeDepth();
  for (int i = 0; i < F.N; ++i) {
    if (F.dynamic[i] || F.depth[i] <= 0 || F.depth[i] >= close) continue;
    if (F.points[i] && !F.outlier[i]) ++tracked_close;
    else ++untracked_close;
  }
  // A young map has few points yet (people covered much of the view while it was made): it
  // takes a keyframe whenever close points go untracked, a mature one waits closeMinFrames.
  const int close_gap = youngMap(F) ? 0 : opt_.close_min_frames;
  const bool need_close = F.id >= last_kf_frame_id_ + close_gap &&
                          tracked_close < opt_.close_tracked_max &&
                          untracked_close > opt_.close_untracked_min;
  const double ratio = n_kfs < 2 ? kRefRatioFirst : opt_.ref_ratio;
  const bool c1a = F.id >= last_kf_frame_id_ + max_frames_;
  const bool c1b = F.id >= last_kf_frame_id_ + min_frames_ && idle;
  const bool c1c = inliers_ < ref_matches * kRefRatioLow || need_close;
  const bool c2 = (inliers_ < ref_matches * ratio || need_close) && inliers_ > kKeyFrameMinInliers;
  if (!((c1a || c1b || c1c) && c2)) return false;
  if (idle) return true;
  mapper_->interruptBA();
  return mapper_->queued() < static_cast<size_t>(mapper_->queueCapacity());
}

bool Tracking::mayMakeKeyFramePoint(const Frame& F, int i) const {
  // A young map made while people filled the view needs every static point it can get.
  if (youngMap(F)) return true;
  if (opt_.moved_points_withheld && F.testedMoving(i)) return false;
  if (!opt_.boxed_points_static_only || F.boxed.empty() || !F.boxed[i]) return true;
  return !F.seenMoving(i);
}

void Tracking::createNewKeyFrame(Frame& F) {
  auto kf = std::make_shared<KeyFrame>(map_.newKeyFrameId(), F);
  computeBow(voc_.get(), kf->f);
  ref_kf_ = kf;
  // Close points with depth become map points right away (ORB-SLAM2 CreateNewKeyFrame):
  // the closest ones first, all those nearer than ThDepth, at least Tracking.keyFramePoints.
  const std::vector<std::pair<float, int>> by_depth = F.staticByDepth();
  int n = 0;
  for (const auto& e : by_depth) {
    const int i = e.second;
    const MapPointPtr& cur = kf->f.points[i];
    if (!cur || cur->numObservations() < 1) {
      if (!mayMakeKeyFramePoint(F, i)) {
        ++boxed_withheld_;
        continue;
      }
      if (!createDepthPoint(kf, F, i)) continue;
    }
    ++n;
    if (e.first > cam_.closeDepth() && n > opt_.keyframe_points) break;
  }
  // Map points that now project onto a dynamic keypoint are marked in this keyframe: they are
  // on something that moves and are no longer used for tracking.
  for (const auto& mp : dynamic_hits_)
    if (mp && !mp->bad) mp->dynamic = true;
  dynamic_hits_.clear();
  mapper_->insertKeyFrame(kf);
  last_kf_ = kf;
  last_kf_frame_id_ = F.id;
}

void Tracking::record(const Frame& F) {
  FrameRecord r;
  r.stamp = F.stamp;
  r.T_wc = F.Twc();
  if (ref_kf_ && !ref_kf_->bad) {
    r.ref = ref_kf_;
    r.T_cr = F.T_cw * ref_kf_->Twc();
  }
  records_.push_back(r);
  last_ref_ = r.ref;
  T_lr_ = r.T_cr;
}

Trajectory Tracking::trajectory() const {
  Trajectory out;
  out.reserve(records_.size());
  for (const auto& r : records_) {
    StampedPose sp;
    sp.stamp = r.stamp;
    sp.T_wc = r.T_wc;
    if (r.ref) {
      // Follow erased keyframes to their parents (their pose relative to the parent is kept).
      Pose T_rr = Pose::Identity();
      const KeyFramePtr ref = liveAncestor(r.ref, &T_rr);
      if (ref) sp.T_wc = (r.T_cr * T_rr * ref->Tcw()).inverse();
    }
    if (finitePose(sp.T_wc)) out.push_back(sp);
  }
  return out;
}

void Tracking::resetKeepTrajectory() {
  // Freeze the trajectory so far as absolute poses, then forget the old map.
  Trajectory t = trajectory();
  records_.clear();
  for (const auto& sp : t) {
    FrameRecord r;
    r.stamp = sp.stamp;
    r.T_wc = sp.T_wc;
    records_.push_back(r);
  }
  state_ = TrackingState::NotInitialized;
  has_last_ = false;
  last_ = Frame();
  ref_kf_.reset();
  last_kf_.reset();
  last_ref_.reset();
  last_kf_frame_id_ = -1;
  init_frame_id_ = -1;
  init_kf_id_ = -1;
  last_tracked_id_ = -1;
  last_reloc_frame_id_ = -1;  // a relocalisation in the old map says nothing of the new one
  forgetMotion();
  failures_in_row_ = 0;
  lost_frames_in_row_ = 0;
  local_kfs_.clear();
  local_points_.clear();
  dynamic_hits_.clear();
  temporary_points_.clear();
  ++resets_;
}

void Tracking::resetAll() {
  resetKeepTrajectory();
  records_.clear();
  frozen_keyframes_.clear();
  has_last_good_ = false;
  has_last_stamp_ = false;
}

void Tracking::startInLoadedMap() {
  const size_t resets = resets_;
  resetAll();
  resets_ = resets;
  state_ = TrackingState::Lost;
}

}  // namespace slam
}  // namespace yolo_slam
