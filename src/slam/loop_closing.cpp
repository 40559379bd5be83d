#include "yolo_slam/slam/loop_closing.h"

#include "yolo_slam/common/log.h"
#include "yolo_slam/optimization/bundle_adjustment.h"
#include "yolo_slam/optimization/pose_graph.h"
#include "yolo_slam/optimization/pose_optimizer.h"
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/local_mapping.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/slam/matcher.h"
#include "yolo_slam/slam/observation.h"
#include "yolo_slam/vocabulary/bow_matcher.h"
#include "yolo_slam/vocabulary/keyframe_database.h"
#include "yolo_slam/vocabulary/vocabulary.h"
#include "yolo_slam/common/thread_name.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <set>
#include <unordered_map>

namespace yolo_slam {
namespace slam {

LoopClosing::LoopClosing(Map& map, const CameraModel& cam, const LoopClosingOptions& opt,
                         LocalMapping* mapper, RunMode mode)
    : map_(map), cam_(cam), opt_(opt), mapper_(mapper), mode_(mode) {}

LoopClosing::~LoopClosing() { stop(); }

void LoopClosing::start() {
  std::lock_guard<std::mutex> lk(queue_mutex_);
  if (thread_.joinable()) return;
  stop_ = false;
  running_ = true;
  if (mode_ == RunMode::Threaded) thread_ = std::thread([this] {
    nameThisThread("ys_loop_close");
    run();
  });
}

void LoopClosing::stop() {
  {
    std::lock_guard<std::mutex> lk(queue_mutex_);
    stop_ = true;
    running_ = false;
    queue_.clear();
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  stopGlobalBA();
}

void LoopClosing::insertKeyFrame(const KeyFramePtr& kf) {
  {
    std::lock_guard<std::mutex> lk(queue_mutex_);
    if (stop_ || !running_) return;
    queue_.push_back(kf);
  }
  cv_.notify_all();
}

void LoopClosing::processQueued() {
  if (mode_ != RunMode::Sequential) return;
  std::unique_lock<std::mutex> lk(queue_mutex_);
  while (!stop_ && !queue_.empty()) processFront(lk);
}

void LoopClosing::waitIdle() {
  if (mode_ == RunMode::Sequential) return;
  while (true) {
    {
      std::unique_lock<std::mutex> lk(queue_mutex_);
      if (running_) cv_.wait(lk, [this] { return stop_ || (queue_.empty() && !busy_); });
    }
    // A global BA started by the last correction ends by itself; only its owner joins it.
    if (!gba_running_.load()) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

void LoopClosing::clear() {
  std::lock_guard<std::mutex> lk(queue_mutex_);
  queue_.clear();
  groups_.clear();
  last_loop_kf_id_ = -1;
  matched_kf_.reset();
  current_matches_.clear();
  loop_points_.clear();
}

size_t LoopClosing::loopsClosed() const { return lockedCopy(queue_mutex_, loops_closed_); }
size_t LoopClosing::globalBundleAdjustments() const { return lockedCopy(queue_mutex_, gba_done_); }
std::vector<std::pair<long, long>> LoopClosing::loops() const { return lockedCopy(queue_mutex_, loops_); }

void LoopClosing::run() {
  std::unique_lock<std::mutex> lk(queue_mutex_);
  while (true) {
    cv_.wait(lk, [this] { return stop_ || !queue_.empty(); });
    if (stop_) break;
    processFront(lk);
  }
  busy_ = false;
  cv_.notify_all();
}

void LoopClosing::processFront(std::unique_lock<std::mutex>& lk) {
  KeyFramePtr kf = queue_.front();
  queue_.pop_front();
  busy_ = true;
  lk.unlock();
  processOne(kf);
  lk.lock();
  busy_ = false;
  cv_.notify_all();
}

bool LoopClosing::processOne(const KeyFramePtr& kf) {
  {
    std::lock_guard<std::mutex> ml(map_.update_mutex);
    if (!kf || kf->bad) return false;
    std::vector<KeyFramePtr> cands = detectLoop(kf);
    if (cands.empty()) return false;
    // Candidates must survive until the correction (ORB-SLAM2 SetNotErase).
    kf->not_erase = true;
    if (!computeSE3(kf, cands)) {
      kf->not_erase = false;
      return false;
    }
  }
  correctLoop(kf);
  return true;
}

// ---------------------------------------------------------------------------------------------
// Detection (ORB-SLAM2 DetectLoop / KeyFrameDatabase::DetectLoopCandidates).

namespace {
// Whether ids and prev (sorted) share an id.
bool overlaps(const std::vector<long>& ids, const std::vector<long>& prev) {
  for (long id : ids)
    if (std::binary_search(prev.begin(), prev.end(), id)) return true;
  return false;
}
}  // namespace

std::vector<KeyFramePtr> LoopClosing::detectLoop(const KeyFramePtr& kf) {
  vocabulary::KeyFrameDatabase* db = map_.keyFrameDatabase();
  if (!db || kf->f.bow.empty()) return {};
  if (static_cast<long>(map_.numKeyFrames()) <= opt_.min_keyframes ||
      (last_loop_kf_id_ >= 0 && kf->id < last_loop_kf_id_ + opt_.min_keyframes))
    return {};

  // The bar: the lowest score against the covisible keyframes (how similar a place must look
  // to be "the same"), at least the configured floor.
  double min_score = 1.0;
  bool any = false;
  for (const auto& nb : kf->ordered_connections) {
    if (nb->bad || nb->f.bow.empty()) continue;
    min_score = std::min(min_score, vocabulary::Vocabulary::score(kf->f.bow.bow, nb->f.bow.bow));
    any = true;
  }
  if (!any) min_score = 0;
  min_score = std::max(min_score, opt_.min_score);

  std::set<long> excluded{kf->id};
  for (const auto& c : kf->connections) excluded.insert(c.first->id);
  vocabulary::QueryOptions q;
  q.min_score = min_score;
  q.exclude = [&excluded](long id) { return excluded.count(id) > 0; };
  const auto hits = db->query(kf->f.bow.bow, 0, q);

  // Group each hit with its best covisibles; keep groups scoring > 0.75 x the best.
  return consistentCandidates(covisibilityGroupCandidates(map_, hits));
}

std::vector<KeyFramePtr> LoopClosing::consistentCandidates(const std::vector<KeyFramePtr>& cands) {
  // A candidate's group (itself + covisibles) must overlap a group that was already consistent
  // for the previous keyframe; `consistency` keyframes in a row.
  std::vector<ConsistentGroup> next;
  std::vector<KeyFramePtr> enough;
  std::vector<bool> group_extended(groups_.size(), false);
  for (const auto& c : cands) {
    ConsistentGroup g;
    g.kfs.push_back(c->id);
    for (const auto& nb : c->connections) g.kfs.push_back(nb.first->id);
    std::sort(g.kfs.begin(), g.kfs.end());
    bool consistent_for_any = false, added = false;
    for (size_t i = 0; i < groups_.size(); ++i) {
      if (!overlaps(g.kfs, groups_[i].kfs)) continue;
      consistent_for_any = true;
      const int count = groups_[i].count + 1;
      if (!group_extended[i]) {
        ConsistentGroup ng = g;
        ng.count = count;
        next.push_back(ng);
        group_extended[i] = true;
      }
      if (count >= opt_.consistency && !added) {
        enough.push_back(c);
        added = true;
      }
    }
    if (!consistent_for_any) next.push_back(g);  // count 0: starts a new group
  }
  groups_ = std::move(next);
  return enough;
}

// ---------------------------------------------------------------------------------------------
// Geometric verification (ORB-SLAM2 ComputeSim3 with SE3).

namespace {

struct Match3D {
  size_t i1, i2;             // keypoint in current / in candidate
  MapPointPtr mp1, mp2;
  Eigen::Vector3d P1, P2;    // camera coordinates in each keyframe
};

// A rigid transform P1 = T12 * P2 and the number of matches it explains.
struct Se3Fit {
  Pose T12 = Pose::Identity();
  int inliers = 0;
};

// An inlier reprojects within chi2(2 dof, 99%) in both keyframes (ORB-SLAM2 Sim3Solver: 9.21).
constexpr double kChi2Inlier = 9.21;

bool reprojOk(const CameraModel& cam, const Frame& f, size_t idx, const Eigen::Vector3d& Pc) {
  if (!(Pc.z() > 0)) return false;
  const Eigen::Vector2d uv = cam.project(Pc);
  const double ex = uv.x() - f.kps[idx].pt.x, ey = uv.y() - f.kps[idx].pt.y;
  return (ex * ex + ey * ey) * f.pyramid->inv_sigma2[f.kps[idx].octave] < kChi2Inlier;
}

Pose umeyamaPose(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst) {
  Eigen::Matrix3Xd a(3, src.size()), b(3, dst.size());
  for (size_t i = 0; i < src.size(); ++i) {
    a.col(i) = src[i];
    b.col(i) = dst[i];
  }
  Pose T = Pose::Identity();
  T.matrix() = Eigen::umeyama(a, b, false);
  return T;
}

// The transform P1 = T12 * P2 fitted to the matches m[k], k in `ks`.
template <class Indices>
Pose fitOn(const std::vector<Match3D>& m, const Indices& ks) {
  std::vector<Eigen::Vector3d> src, dst;
  for (size_t k : ks) {
    src.push_back(m[k].P2);
    dst.push_back(m[k].P1);
  }
  return umeyamaPose(src, dst);
}

std::vector<uint8_t> usableWithPoint(const KeyFrame& kf) {
  std::vector<uint8_t> u(kf.f.N, 0);
  for (int i = 0; i < kf.f.N; ++i) {
    const MapPointPtr& mp = kf.f.points[i];
    u[i] = mp && !mp->bad && !mp->dynamic && !kf.f.dynamic[i];
  }
  return u;
}

// Nearest-neighbour ratio of SearchByBoW between keyframes (ORB-SLAM2 ComputeSim3: 0.75).
constexpr float kBowRatio = 0.75f;

// SearchByBoW between the current keyframe and a candidate, kept where both keypoints have
// distinct map points. n_bow: the BoW matches before that.
std::vector<Match3D> matchesWithPoints(const KeyFrame& kf, const KeyFrame& cand,
                                       const std::vector<uint8_t>& use1, size_t* n_bow) {
  const std::vector<uint8_t> use2 = usableWithPoint(cand);
  vocabulary::BowSide a{&kf.f.bow.features, &kf.f.descriptors, &kf.f.kps, &use1};
  vocabulary::BowSide b{&cand.f.bow.features, &cand.f.descriptors, &cand.f.kps, &use2};
  vocabulary::BowMatchOptions bo;
  bo.nn_ratio = kBowRatio;
  const auto bm = vocabulary::searchByBow(a, b, bo);
  *n_bow = bm.size();
  std::vector<Match3D> m;
  for (const auto& x : bm) {
    Match3D q;
    q.i1 = x.a;
    q.i2 = x.b;
    q.mp1 = kf.f.points[x.a];
    q.mp2 = cand.f.points[x.b];
    if (!q.mp1 || !q.mp2 || q.mp1 == q.mp2) continue;
    q.P1 = kf.Tcw() * q.mp1->Xw;
    q.P2 = cand.Tcw() * q.mp2->Xw;
    m.push_back(q);
  }
  return m;
}

// Matches that reproject within kChi2Inlier in both keyframes under T12 (appended to `out`
// if given); returns their number.
int se3Inliers(const CameraModel& cam, const Frame& f1, const Frame& f2, const std::vector<Match3D>& m,
               const Pose& T12, std::vector<size_t>* out) {
  const Pose T21 = T12.inverse();
  int n = 0;
  for (size_t k = 0; k < m.size(); ++k) {
    if (reprojOk(cam, f1, m[k].i1, T12 * m[k].P2) && reprojOk(cam, f2, m[k].i2, T21 * m[k].P1)) {
      ++n;
      if (out) out->push_back(k);
    }
  }
  return n;
}

// RANSAC iterations (ORB-SLAM2 ComputeSim3: 300); a hypothesis explaining this share of the
// matches ends the search early (this project's choice).
constexpr int kRansacIterations = 300;
constexpr double kRansacEnoughShare = 0.9;

// 3-point RANSAC on P1 = T12 * P2 (Umeyama/Horn on the samples).
Se3Fit ransacSE3(const CameraModel& cam, const Frame& f1, const Frame& f2, const std::vector<Match3D>& m,
                 std::mt19937& rng) {
  std::uniform_int_distribution<size_t> pick(0, m.size() - 1);
  Se3Fit best;
  for (int it = 0; it < kRansacIterations; ++it) {
    size_t s[3] = {pick(rng), pick(rng), pick(rng)};
    if (s[0] == s[1] || s[0] == s[2] || s[1] == s[2]) continue;
    const Pose T = fitOn(m, s);
    if (!T.matrix().allFinite()) continue;
    const int n = se3Inliers(cam, f1, f2, m, T, nullptr);
    if (n > best.inliers) {
      best.inliers = n;
      best.T12 = T;
      if (n > kRansacEnoughShare * m.size()) break;
    }
  }
  return best;
}

// Refits the transform on all inliers of `fit`; kept if it explains no fewer matches.
void refitOnInliers(const CameraModel& cam, const Frame& f1, const Frame& f2, const std::vector<Match3D>& m,
                    Se3Fit& fit) {
  std::vector<size_t> inl;
  se3Inliers(cam, f1, f2, m, fit.T12, &inl);
  const Pose T = fitOn(m, inl);
  if (T.matrix().allFinite() && se3Inliers(cam, f1, f2, m, T, nullptr) >= fit.inliers) fit.T12 = T;
}

// Pose-only refinement of F on its associations; outlier associations are dropped. Returns the
// inliers (0 when the optimisation failed; F then keeps its pose and associations).
int refinePose(const CameraModel& cam, Frame& F) {
  std::vector<optimization::PoseObservation> obs;
  std::vector<int> idx;
  for (int i = 0; i < F.N; ++i) {
    if (!F.points[i]) continue;
    obs.push_back(poseObservation(F, i, F.points[i]->Xw));
    idx.push_back(i);
  }
  std::vector<bool> out;
  Pose T = F.T_cw;
  const int n = optimization::optimizePose(cam, T, obs, out);
  if (n <= 0) return 0;
  F.setPose(T);
  for (size_t k = 0; k < idx.size(); ++k)
    if (out[k]) F.points[idx[k]].reset();
  return n;
}

// The live, static points of the candidate and its covisibles, each once.
std::vector<MapPointPtr> loopSidePoints(const KeyFramePtr& cand) {
  std::vector<MapPointPtr> loop_points;
  std::set<long> seen_points;
  std::vector<KeyFramePtr> loop_kfs = cand->ordered_connections;
  loop_kfs.push_back(cand);
  for (const auto& lk : loop_kfs) {
    if (lk->bad) continue;
    for (const auto& mp : lk->mapPoints())
      if (!mp->bad && !mp->dynamic && seen_points.insert(mp->id).second) loop_points.push_back(mp);
  }
  return loop_points;
}

// Projection search of the loop side's points: minimum viewing cosine (ORB-SLAM2: 0.5), window
// and nearest-neighbour ratio (this project's choice).
constexpr double kLoopViewCos = 0.5;
constexpr double kLoopWindow = 1.0;
constexpr double kLoopRatio = 0.9;

// Projection search of the loop points not matched yet into F; returns F's matches in all.
int searchLoopPoints(Frame& F, const std::vector<MapPointPtr>& loop_points) {
  std::set<long> matched;
  for (const auto& mp : F.points)
    if (mp) matched.insert(mp->id);
  std::vector<matcher::Projection> proj;
  for (const auto& mp : loop_points) {
    if (matched.count(mp->id)) continue;
    matcher::Projection p;
    if (matcher::projectInFrame(F, mp, kLoopViewCos, p)) proj.push_back(p);
  }
  matcher::searchProjections(F, proj, kLoopWindow, kLoopRatio);
  int total = 0;
  for (const auto& mp : F.points) total += mp ? 1 : 0;
  return total;
}

}  // namespace

bool LoopClosing::computeSE3(const KeyFramePtr& kf, const std::vector<KeyFramePtr>& cands) {
  const std::vector<uint8_t> use1 = usableWithPoint(*kf);
  std::mt19937 rng(static_cast<unsigned>(kf->id));
  for (const KeyFramePtr& cand : cands) {
    if (cand->bad || cand->f.bow.empty()) continue;
    if (verifyCandidate(kf, cand, use1, rng)) return true;
  }
  return false;
}

bool LoopClosing::verifyCandidate(const KeyFramePtr& kf, const KeyFramePtr& cand,
                                  const std::vector<uint8_t>& use1, std::mt19937& rng) {
  size_t n_bow = 0;
  const std::vector<Match3D> m = matchesWithPoints(*kf, *cand, use1, &n_bow);
  if (static_cast<int>(m.size()) < opt_.min_bow_matches) return false;
  Se3Fit fit = ransacSE3(cam_, kf->f, cand->f, m, rng);
  if (fit.inliers < opt_.min_ransac_inliers) return false;
  refitOnInliers(cam_, kf->f, cand->f, m, fit);

  // The current keyframe's pose in the loop side's frame, refined on the inlier matches (the
  // current keypoints against the loop points), then more matches by projection.
  Frame F = kf->f;
  std::fill(F.points.begin(), F.points.end(), nullptr);
  F.outlier.assign(F.N, false);
  F.setPose(fit.T12 * cand->Tcw());
  std::vector<size_t> inl;
  se3Inliers(cam_, kf->f, cand->f, m, fit.T12, &inl);
  for (size_t k : inl) F.points[m[k].i1] = m[k].mp2;
  if (refinePose(cam_, F) < opt_.min_ransac_inliers) return false;

  std::vector<MapPointPtr> loop_points = loopSidePoints(cand);
  if (searchLoopPoints(F, loop_points) < opt_.min_matches) return false;
  const int final_inliers = refinePose(cam_, F);
  if (final_inliers < opt_.min_matches) return false;
  double corr_m = 0, corr_deg = 0;
  if (!withinDriftBound(*kf, *cand, F.T_cw, corr_m, corr_deg)) return false;
  log::info("loop: keyframe %ld matches keyframe %ld (%d BoW, %d RANSAC, %d final), "
               "correction %.3f m %.2f deg", kf->id, cand->id, static_cast<int>(n_bow), fit.inliers,
               final_inliers, corr_m, corr_deg);
  matched_kf_ = cand;
  T_cw_corrected_ = F.T_cw;
  current_matches_ = F.points;
  loop_points_ = std::move(loop_points);
  return true;
}

bool LoopClosing::withinDriftBound(const KeyFrame& kf, const KeyFrame& cand, const Pose& T_cw,
                                   double& corr_m, double& corr_deg) const {
  // Repeated textures (synthetic rooms, tiled floors) can pass every test of the verification
  // with a transform no RGB-D odometry could have drifted by; such a "loop" would wreck the map.
  const Pose D = T_cw * kf.Twc();
  corr_m = D.translation().norm();
  corr_deg = rotationAngle(D.linear()) * 180 / M_PI;
  const bool too_large = corr_m > opt_.max_correction_m || corr_deg > opt_.max_correction_deg;
  if (!too_large) return true;
  log::info("loop: keyframe %ld vs %ld rejected: correction %.3f m %.1f deg above the "
               "drift bound (LoopClosing.maxCorrectionM/Deg)", kf.id, cand.id, corr_m, corr_deg);
  return false;
}

// ---------------------------------------------------------------------------------------------
// Correction (ORB-SLAM2 CorrectLoop with SE3).

// The current keyframe with its covisibles, moved rigidly with it onto the loop side.
struct LoopClosing::Neighbourhood {
  std::vector<KeyFramePtr> kfs;
  std::set<long> ids;
  std::map<long, Pose> Tcw_before;              // uncorrected poses
  std::unordered_map<long, long> corrected_by;  // point id -> keyframe whose correction moved it
};

void LoopClosing::pauseMapping() {
  if (!mapper_) return;
  mapper_->pauseForLoop();
  mapper_->waitUntilPaused();
}

void LoopClosing::correctLoop(const KeyFramePtr& kf) {
  // A running global BA works on a map about to change: abort it.
  stopGlobalBA();
  pauseMapping();
  {
    std::lock_guard<std::mutex> ml(map_.update_mutex);
    const KeyFramePtr loop_kf = matched_kf_;
    if (kf->bad || !loop_kf || loop_kf->bad) {
      kf->not_erase = false;
      if (mapper_) mapper_->resumeFromLoop();
      return;
    }
    kf->updateConnections();
    const Neighbourhood n = moveNeighbourhood(kf);
    fuseCurrentMatches(kf);
    fuseLoopPoints(n.kfs);
    const Links new_links = linkLoop(kf, loop_kf, n);
    const auto kfs = map_.keyframes();
    std::map<long, Pose> T_wc_start;
    for (const auto& k : kfs) T_wc_start[k->id] = k->Twc();
    const std::map<long, Pose> T_wc = optimizeEssentialGraph(kf, loop_kf, kfs, T_wc_start, n, new_links);
    writeBackCorrection(kfs, T_wc_start, T_wc, n.corrected_by);
    kf->not_erase = false;
    last_loop_kf_id_ = kf->id;
    groups_.clear();
    std::lock_guard<std::mutex> lk(queue_mutex_);
    ++loops_closed_;
    loops_.emplace_back(kf->id, loop_kf->id);
  }
  if (mapper_) mapper_->resumeFromLoop();
  if (opt_.global_ba) startGlobalBA(kf->id);
}

LoopClosing::Neighbourhood LoopClosing::moveNeighbourhood(const KeyFramePtr& kf) {
  Neighbourhood n;
  n.kfs = kf->ordered_connections;
  n.kfs.push_back(kf);
  for (const auto& c : n.kfs) n.ids.insert(c->id);
  std::map<long, Pose> Tcw_after;  // corrected
  const Pose T_wc_cur = kf->Twc();
  for (const auto& c : n.kfs) {
    n.Tcw_before[c->id] = c->Tcw();
    Tcw_after[c->id] = c == kf ? T_cw_corrected_ : c->Tcw() * T_wc_cur * T_cw_corrected_;
  }
  for (const auto& c : n.kfs) {
    const Pose T_w_corr = Tcw_after[c->id].inverse() * n.Tcw_before[c->id];
    for (const auto& mp : c->mapPoints()) {
      if (n.corrected_by.count(mp->id)) continue;
      mp->Xw = T_w_corr * mp->Xw;
      n.corrected_by[mp->id] = c->id;
    }
    c->f.setPose(Tcw_after[c->id]);
  }
  for (const auto& c : n.kfs)
    for (const auto& mp : c->mapPoints()) mp->updateNormalAndDepth();
  return n;
}

void LoopClosing::fuseCurrentMatches(const KeyFramePtr& kf) {
  for (size_t i = 0; i < current_matches_.size() && i < kf->f.points.size(); ++i) {
    MapPointPtr loop_mp = current_matches_[i];
    if (!loop_mp) continue;
    loop_mp = MapPoint::resolve(loop_mp);
    if (!loop_mp || loop_mp->bad) continue;
    MapPointPtr cur = kf->f.points[i];
    if (cur && !cur->bad) {
      if (cur != loop_mp) map_.replaceMapPoint(cur, loop_mp);
    } else if (!loop_mp->inKeyFrame(kf.get())) {
      Map::addObservation(loop_mp, kf, i);
      loop_mp->computeDistinctiveDescriptor();
    }
  }
}

void LoopClosing::fuseLoopPoints(const std::vector<KeyFramePtr>& neighbourhood) {
  // Window of ORB-SLAM2 SearchAndFuse.
  constexpr double kLoopFuseWindow = 4.0;
  std::vector<MapPointPtr> loop_points;
  for (const auto& mp : loop_points_) {
    MapPointPtr p = MapPoint::resolve(mp);
    if (p && !p->bad) loop_points.push_back(p);
  }
  for (const auto& c : neighbourhood)
    if (!c->bad) matcher::fuse(map_, c, loop_points, kLoopFuseWindow);
}

LoopClosing::Links LoopClosing::linkLoop(const KeyFramePtr& kf, const KeyFramePtr& loop_kf,
                                         const Neighbourhood& n) {
  std::map<long, std::set<long>> prev_neighbours;
  for (const auto& c : n.kfs)
    for (const auto& nb : c->ordered_connections) prev_neighbours[c->id].insert(nb->id);
  Links new_links;
  for (const auto& c : n.kfs) {
    if (c->bad) continue;
    c->updateConnections();
    for (const auto& nb : c->ordered_connections) {
      if (n.ids.count(nb->id) || prev_neighbours[c->id].count(nb->id)) continue;
      new_links.emplace_back(c->id, nb->id);
    }
  }
  kf->loop_edges.insert(loop_kf);
  loop_kf->loop_edges.insert(kf);
  loop_kf->not_erase = true;  // loop edges keep both ends (ORB-SLAM2)
  return new_links;
}

std::vector<optimization::PoseGraphEdge> LoopClosing::essentialGraphEdges(
    const KeyFramePtr& kf, const KeyFramePtr& loop_kf, const std::vector<KeyFramePtr>& kfs,
    const std::map<long, Pose>& T_wc, const std::map<long, Pose>& T_wc_meas, const Links& new_links) const {
  std::vector<optimization::PoseGraphEdge> edges;
  std::set<std::pair<long, long>> have;
  auto add_edge = [&](long a, long b, const std::map<long, Pose>& poses) {
    if (a == b) return;
    const auto key = std::make_pair(std::min(a, b), std::max(a, b));
    if (!T_wc.count(a) || !T_wc.count(b) || !have.insert(key).second) return;
    optimization::PoseGraphEdge e;
    e.from = a;
    e.to = b;
    e.T_from_to = poses.at(a).inverse() * poses.at(b);
    edges.push_back(e);
  };
  for (const auto& l : new_links) add_edge(l.first, l.second, T_wc);
  add_edge(kf->id, loop_kf->id, T_wc);
  for (const auto& k : kfs) {
    if (k->parent && !k->parent->bad) add_edge(k->parent->id, k->id, T_wc_meas);
    for (const auto& le : k->loop_edges)
      if (!le->bad) add_edge(k->id, le->id, T_wc_meas);
    for (size_t j = 0; j < k->ordered_connections.size(); ++j) {
      if (k->ordered_weights[j] < opt_.covisibility_weight) break;
      add_edge(k->id, k->ordered_connections[j]->id, T_wc_meas);
    }
  }
  return edges;
}

std::map<long, Pose> LoopClosing::optimizeEssentialGraph(const KeyFramePtr& kf, const KeyFramePtr& loop_kf,
                                                         const std::vector<KeyFramePtr>& kfs,
                                                         const std::map<long, Pose>& T_wc_start,
                                                         const Neighbourhood& n, const Links& new_links) {
  // Nodes start at the corrected poses; edges are measured on the uncorrected ones (the
  // odometry before the loop), new links on the corrected ones.
  std::map<long, Pose> T_wc = T_wc_start, T_wc_meas;
  for (const auto& k : kfs) {
    auto it = n.Tcw_before.find(k->id);
    T_wc_meas[k->id] = it != n.Tcw_before.end() ? it->second.inverse() : k->Twc();
  }
  const std::vector<optimization::PoseGraphEdge> edges =
      essentialGraphEdges(kf, loop_kf, kfs, T_wc, T_wc_meas, new_links);
  std::set<long> fixed{loop_kf->id};
  if (map_.origin() && !map_.origin()->bad) fixed.insert(map_.origin()->id);
  try {
    optimization::optimizePoseGraph(T_wc, edges, fixed, opt_.pose_graph_iterations);
  } catch (const std::exception& e) {
    log::warn("loop %ld-%ld: essential graph not optimised: %s", kf->id,
                 loop_kf->id, e.what());
    T_wc = T_wc_start;
  }
  return T_wc;
}

void LoopClosing::writeBackCorrection(const std::vector<KeyFramePtr>& kfs, const std::map<long, Pose>& T_wc_start,
                                      const std::map<long, Pose>& T_wc,
                                      const std::unordered_map<long, long>& corrected_by) {
  // Keyframes, then points through the keyframe that last moved them.
  std::unordered_map<long, Pose> T_corr;  // world correction per keyframe: new T_wc * old T_cw
  for (const auto& k : kfs) {
    const Pose& Tn = T_wc.at(k->id);
    if (!Tn.matrix().allFinite()) continue;
    T_corr[k->id] = Tn * T_wc_start.at(k->id).inverse();
    k->f.setPose(Tn.inverse());
  }
  for (const auto& mp : map_.mapPoints()) {
    if (mp->bad) continue;
    long ref = -1;
    auto cb = corrected_by.find(mp->id);
    if (cb != corrected_by.end()) ref = cb->second;
    else if (mp->ref_kf) ref = mp->ref_kf->id;
    auto it = T_corr.find(ref);
    if (it == T_corr.end()) continue;
    mp->Xw = it->second * mp->Xw;
    mp->updateNormalAndDepth();
  }
}

void LoopClosing::startGlobalBA(long loop_kf_id) {
  gba_stop_.store(false);
  gba_running_.store(true);
  if (mode_ == RunMode::Sequential) runGlobalBA(loop_kf_id);
  else gba_thread_ = std::thread([this, loop_kf_id] {
    nameThisThread("ys_global_ba");
    runGlobalBA(loop_kf_id);
  });
}

void LoopClosing::stopGlobalBA() {
  gba_stop_.store(true);
  if (gba_thread_.joinable()) gba_thread_.join();
  gba_running_.store(false);
}

// ---------------------------------------------------------------------------------------------
// Global BA (ORB-SLAM2 RunGlobalBundleAdjustment): on a copy, then written back with the
// corrections propagated through the spanning tree to keyframes/points created meanwhile.

void LoopClosing::runGlobalBA(long loop_kf_id) {
  optimization::BaProblem problem;
  {
    std::lock_guard<std::mutex> ml(map_.update_mutex);
    problem = globalProblem();
  }
  optimization::BaResult res;
  try {
    // Only the solve runs niced (LoopClosing.threadNice): it holds no lock.
    const int nice = mode_ == RunMode::Threaded ? opt_.thread_nice : 0;
    runAtLowerPriority(nice, "ys_global_ba_s", "LoopClosing.threadNice", [&] {
      res = optimization::globalBundleAdjustment(cam_, problem, opt_.global_ba_iterations, gba_stop_);
    });
  } catch (const std::exception& e) {
    log::warn("global BA after loop at keyframe %ld failed: %s", loop_kf_id, e.what());
    gba_running_.store(false);
    return;
  }
  if (res.stopped || gba_stop_.load()) {
    gba_running_.store(false);
    return;
  }
  pauseMapping();
  {
    std::lock_guard<std::mutex> ml(map_.update_mutex);
    const std::unordered_map<long, Pose> corr = writeBackKeyFrames(problem);
    writeBackPoints(problem, corr);
    std::lock_guard<std::mutex> lk(queue_mutex_);
    ++gba_done_;
  }
  if (mapper_) mapper_->resumeFromLoop();
  gba_running_.store(false);
}

optimization::BaProblem LoopClosing::globalProblem() const {
  optimization::BaProblem problem;
  std::set<long> in_problem_kf;
  const KeyFramePtr origin = map_.origin();
  for (const auto& k : map_.keyframes()) {
    if (k->bad) continue;
    problem.keyframes.push_back({k->id, k->Tcw(), k == origin});
    in_problem_kf.insert(k->id);
  }
  for (const auto& mp : map_.mapPoints()) {
    if (mp->bad || mp->dynamic) continue;
    bool any = false;
    for (const auto& o : mp->observations) {
      const KeyFramePtr& k = o.first;
      if (k->bad || !in_problem_kf.count(k->id)) continue;
      problem.observations.push_back(baObservation(k->f, o.second, k->id, mp->id));
      any = true;
    }
    if (any) problem.points.push_back({mp->id, mp->Xw});
  }
  return problem;
}

std::unordered_map<long, Pose> LoopClosing::writeBackKeyFrames(const optimization::BaProblem& problem) {
  std::unordered_map<long, Pose> after;
  for (const auto& bk : problem.keyframes)
    if (bk.T_cw.matrix().allFinite()) after[bk.id] = bk.T_cw;
  // Depth-first over the spanning tree from the origin: keyframes not in the problem follow
  // their parent's correction.
  std::unordered_map<long, Pose> before;  // T_cw before the write-back
  std::unordered_map<long, Pose> corr;    // T_wc_new * T_cw_old per keyframe
  std::vector<KeyFrame*> stack;
  if (map_.origin()) stack.push_back(map_.origin().get());
  std::set<long> visited;
  while (!stack.empty()) {
    KeyFrame* k = stack.back();
    stack.pop_back();
    if (!visited.insert(k->id).second) continue;
    for (KeyFrame* ch : k->children) stack.push_back(ch);
    if (k->bad) continue;
    before[k->id] = k->Tcw();
    auto it = after.find(k->id);
    Pose Tn;
    if (it != after.end()) {
      Tn = it->second;
    } else if (k->parent && after.count(k->parent->id)) {
      // T_cw_new = T_cp_old * T_pw_new (the child keeps its pose relative to the parent)
      const Pose T_cp = k->Tcw() * before.at(k->parent->id).inverse();
      Tn = T_cp * after.at(k->parent->id);
      after[k->id] = Tn;
    } else {
      continue;
    }
    corr[k->id] = Tn.inverse() * k->Tcw();
    k->f.setPose(Tn);
  }
  return corr;
}

void LoopClosing::writeBackPoints(const optimization::BaProblem& problem,
                                  const std::unordered_map<long, Pose>& corr) {
  std::unordered_map<long, size_t> bp_index;
  for (size_t i = 0; i < problem.points.size(); ++i) bp_index[problem.points[i].id] = i;
  for (const auto& mp : map_.mapPoints()) {
    if (mp->bad) continue;
    auto it = bp_index.find(mp->id);
    if (it != bp_index.end() && problem.points[it->second].Xw.allFinite()) {
      mp->Xw = problem.points[it->second].Xw;
    } else if (mp->ref_kf) {
      auto c = corr.find(mp->ref_kf->id);
      if (c == corr.end()) continue;
      mp->Xw = c->second * mp->Xw;
    }
    mp->updateNormalAndDepth();
  }
}

}  // namespace slam
}  // namespace yolo_slam
