#include "yolo_slam/slam/loop_closing.h"

#include "yolo_slam/optimization/bundle_adjustment.h"
#include "yolo_slam/optimization/pose_graph.h"
#include "yolo_slam/optimization/pose_optimizer.h"
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/local_mapping.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/slam/matcher.h"
#include "yolo_slam/vocabulary/bow_matcher.h"
#include "yolo_slam/vocabulary/keyframe_database.h"
#include "yolo_slam/vocabulary/vocabulary.h"

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
  if (mode_ == RunMode::Threaded) thread_ = std::thread([this] { run(); });
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

size_t LoopClosing::loopsClosed() const {
  std::lock_guard<std::mutex> lk(queue_mutex_);
  return loops_closed_;
}
size_t LoopClosing::globalBundleAdjustments() const {
  std::lock_guard<std::mutex> lk(queue_mutex_);
  return gba_done_;
}
std::vector<std::pair<long, long>> LoopClosing::loops() const {
  std::lock_guard<std::mutex> lk(queue_mutex_);
  return loops_;
}

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
  const std::vector<KeyFramePtr> cands = covisibilityGroupCandidates(map_, hits);

  // Temporal consistency: a candidate's group (itself + covisibles) must overlap a group that
  // was already consistent for the previous keyframe; `consistency` keyframes in a row.
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
      const auto& prev = groups_[i].kfs;
      bool overlap = false;
      for (long id : g.kfs)
        if (std::binary_search(prev.begin(), prev.end(), id)) {
          overlap = true;
          break;
        }
      if (!overlap) continue;
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

bool reprojOk(const CameraModel& cam, const Frame& f, size_t idx, const Eigen::Vector3d& Pc) {
  if (!(Pc.z() > 0)) return false;
  const Eigen::Vector2d uv = cam.project(Pc);
  const double ex = uv.x() - f.kps[idx].pt.x, ey = uv.y() - f.kps[idx].pt.y;
  return (ex * ex + ey * ey) * f.pyramid->inv_sigma2[f.kps[idx].octave] < 9.21;
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

std::vector<uint8_t> usableWithPoint(const KeyFrame& kf) {
  std::vector<uint8_t> u(kf.f.N, 0);
  for (int i = 0; i < kf.f.N; ++i) {
    const MapPointPtr& mp = kf.f.points[i];
    u[i] = mp && !mp->bad && !mp->dynamic && !kf.f.dynamic[i];
  }
  return u;
}

}  // namespace

bool LoopClosing::computeSE3(const KeyFramePtr& kf, const std::vector<KeyFramePtr>& cands) {
  const std::vector<uint8_t> use1 = usableWithPoint(*kf);
  std::mt19937 rng(static_cast<unsigned>(kf->id));
  for (const KeyFramePtr& cand : cands) {
    if (cand->bad || cand->f.bow.empty()) continue;
    const std::vector<uint8_t> use2 = usableWithPoint(*cand);
    vocabulary::BowSide a{&kf->f.bow.features, &kf->f.descriptors, &kf->f.kps, &use1};
    vocabulary::BowSide b{&cand->f.bow.features, &cand->f.descriptors, &cand->f.kps, &use2};
    vocabulary::BowMatchOptions bo;
    bo.nn_ratio = 0.75f;  // ORB-SLAM2 uses 0.75 between keyframes
    const auto bm = vocabulary::searchByBow(a, b, bo);
    if (static_cast<int>(bm.size()) < opt_.min_bow_matches) continue;

    std::vector<Match3D> m;
    for (const auto& x : bm) {
      Match3D q;
      q.i1 = x.a;
      q.i2 = x.b;
      q.mp1 = kf->f.points[x.a];
      q.mp2 = cand->f.points[x.b];
      if (!q.mp1 || !q.mp2 || q.mp1 == q.mp2) continue;
      q.P1 = kf->Tcw() * q.mp1->Xw;
      q.P2 = cand->Tcw() * q.mp2->Xw;
      m.push_back(q);
    }
    if (static_cast<int>(m.size()) < opt_.min_bow_matches) continue;

    // RANSAC: P1 = T12 * P2; inliers reproject within chi2(2, 0.99) in both keyframes.
    auto inliers_of = [&](const Pose& T12, std::vector<size_t>* out) {
      const Pose T21 = T12.inverse();
      int n = 0;
      for (size_t k = 0; k < m.size(); ++k) {
        if (reprojOk(cam_, kf->f, m[k].i1, T12 * m[k].P2) && reprojOk(cam_, cand->f, m[k].i2, T21 * m[k].P1)) {
          ++n;
          if (out) out->push_back(k);
        }
      }
      return n;
    };
    std::uniform_int_distribution<size_t> pick(0, m.size() - 1);
    int best_n = 0;
    Pose best_T = Pose::Identity();
    for (int it = 0; it < 300; ++it) {
      size_t s[3] = {pick(rng), pick(rng), pick(rng)};
      if (s[0] == s[1] || s[0] == s[2] || s[1] == s[2]) continue;
      std::vector<Eigen::Vector3d> src, dst;
      for (size_t k : s) {
        src.push_back(m[k].P2);
        dst.push_back(m[k].P1);
      }
      const Pose T = umeyamaPose(src, dst);
      if (!T.matrix().allFinite()) continue;
      const int n = inliers_of(T, nullptr);
      if (n > best_n) {
        best_n = n;
        best_T = T;
        if (n > 0.9 * m.size()) break;
      }
    }
    if (best_n < opt_.min_ransac_inliers) continue;
    std::vector<size_t> inl;
    inliers_of(best_T, &inl);
    {
      std::vector<Eigen::Vector3d> src, dst;
      for (size_t k : inl) {
        src.push_back(m[k].P2);
        dst.push_back(m[k].P1);
      }
      const Pose T = umeyamaPose(src, dst);
      if (T.matrix().allFinite() && inliers_of(T, nullptr) >= best_n) best_T = T;
    }

    // The current keyframe's pose in the loop side's frame, refined on the inlier matches (the
    // current keypoints against the loop points), then more matches by projection.
    Frame F = kf->f;
    std::fill(F.points.begin(), F.points.end(), nullptr);
    F.outlier.assign(F.N, false);
    F.setPose(best_T * cand->Tcw());
    inl.clear();
    inliers_of(best_T, &inl);
    for (size_t k : inl) F.points[m[k].i1] = m[k].mp2;

    auto optimize = [&]() {
      std::vector<optimization::PoseObservation> obs;
      std::vector<int> idx;
      for (int i = 0; i < F.N; ++i) {
        if (!F.points[i]) continue;
        optimization::PoseObservation o;
        o.Xw = F.points[i]->Xw;
        o.uv = Eigen::Vector2d(F.kps[i].pt.x, F.kps[i].pt.y);
        o.u_right = F.right_u[i] >= 0 ? F.right_u[i] : -1.0;
        o.inv_sigma2 = F.pyramid->inv_sigma2[F.kps[i].octave];
        obs.push_back(o);
        idx.push_back(i);
      }
      std::vector<bool> out;
      Pose T = F.T_cw;
      const int n = optimization::optimizePose(cam_, T, obs, out);
      if (n <= 0) return 0;
      F.setPose(T);
      for (size_t k = 0; k < idx.size(); ++k)
        if (out[k]) F.points[idx[k]].reset();
      return n;
    };
    if (optimize() < opt_.min_ransac_inliers) continue;

    std::vector<MapPointPtr> loop_points;
    std::set<long> seen_points;
    std::vector<KeyFramePtr> loop_kfs = cand->ordered_connections;
    loop_kfs.push_back(cand);
    for (const auto& lk : loop_kfs) {
      if (lk->bad) continue;
      for (const auto& mp : lk->mapPoints())
        if (!mp->bad && !mp->dynamic && seen_points.insert(mp->id).second) loop_points.push_back(mp);
    }
    std::set<long> matched;
    for (const auto& mp : F.points)
      if (mp) matched.insert(mp->id);
    std::vector<matcher::Projection> proj;
    for (const auto& mp : loop_points) {
      if (matched.count(mp->id)) continue;
      matcher::Projection p;
      if (matcher::projectInFrame(F, mp, 0.5, p)) proj.push_back(p);
    }
    matcher::searchProjections(F, proj, 1.0, 0.9);
    int total = 0;
    for (const auto& mp : F.points) total += mp ? 1 : 0;
    if (total < opt_.min_matches) continue;
    const int final_inliers = optimize();
    if (final_inliers < opt_.min_matches) continue;

    // Drift bound: repeated textures (synthetic rooms, tiled floors) can pass every test above
    // with a transform no RGB-D odometry could have drifted by; such a "loop" would wreck the map.
    const Pose D = F.T_cw * kf->Twc();
    const double corr_m = D.translation().norm(), corr_deg = rotationAngle(D.linear()) * 180 / M_PI;
    if (corr_m > opt_.max_correction_m || corr_deg > opt_.max_correction_deg) {
      std::fprintf(stderr, "loop: keyframe %ld vs %ld rejected: correction %.3f m %.1f deg above the "
                   "drift bound (LoopClosing.maxCorrectionM/Deg)\n", kf->id, cand->id, corr_m, corr_deg);
      continue;
    }
    std::fprintf(stderr, "loop: keyframe %ld matches keyframe %ld (%d BoW, %d RANSAC, %d final), "
                 "correction %.3f m %.2f deg\n", kf->id, cand->id, static_cast<int>(bm.size()), best_n,
                 final_inliers, corr_m, corr_deg);
    matched_kf_ = cand;
    T_cw_corrected_ = F.T_cw;
    current_matches_ = F.points;
    loop_points_ = std::move(loop_points);
    return true;
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// Correction (ORB-SLAM2 CorrectLoop with SE3).

void LoopClosing::correctLoop(const KeyFramePtr& kf) {
  // A running global BA works on a map about to change: abort it.
  stopGlobalBA();
  if (mapper_) {
    mapper_->pauseForLoop();
    mapper_->waitUntilPaused();
  }
  {
    std::lock_guard<std::mutex> ml(map_.update_mutex);
    const KeyFramePtr loop_kf = matched_kf_;
    if (kf->bad || !loop_kf || loop_kf->bad) {
      kf->not_erase = false;
      if (mapper_) mapper_->resumeFromLoop();
      return;
    }
    kf->updateConnections();

    // 1. Move the current keyframe's neighbourhood (and the points it sees) rigidly with it.
    std::vector<KeyFramePtr> connected = kf->ordered_connections;
    connected.push_back(kf);
    std::set<long> connected_ids;
    for (const auto& c : connected) connected_ids.insert(c->id);
    std::map<long, Pose> Tcw_before, Tcw_after;  // uncorrected / corrected, connected only
    const Pose T_wc_cur = kf->Twc();
    for (const auto& c : connected) {
      Tcw_before[c->id] = c->Tcw();
      Tcw_after[c->id] = c == kf ? T_cw_corrected_ : c->Tcw() * T_wc_cur * T_cw_corrected_;
    }
    std::unordered_map<long, long> corrected_by;  // point id -> keyframe whose correction moved it
    for (const auto& c : connected) {
      const Pose T_w_corr = Tcw_after[c->id].inverse() * Tcw_before[c->id];
      for (const auto& mp : c->mapPoints()) {
        if (corrected_by.count(mp->id)) continue;
        mp->Xw = T_w_corr * mp->Xw;
        corrected_by[mp->id] = c->id;
      }
      c->f.setPose(Tcw_after[c->id]);
    }
    for (const auto& c : connected)
      for (const auto& mp : c->mapPoints()) mp->updateNormalAndDepth();

    // 2. Fuse the verified matches: the current keyframe's points become the loop side's.
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
    // ... and the loop side's points into the whole corrected neighbourhood.
    std::vector<MapPointPtr> loop_points;
    for (const auto& mp : loop_points_) {
      MapPointPtr p = MapPoint::resolve(mp);
      if (p && !p->bad) loop_points.push_back(p);
    }
    for (const auto& c : connected)
      if (!c->bad) matcher::fuse(map_, c, loop_points, 4.0);

    // 3. New links created by the fusion: the loop edges of the essential graph.
    std::map<long, std::set<long>> prev_neighbours;
    for (const auto& c : connected)
      for (const auto& nb : c->ordered_connections) prev_neighbours[c->id].insert(nb->id);
    std::vector<std::pair<long, long>> new_links;
    for (const auto& c : connected) {
      if (c->bad) continue;
      c->updateConnections();
      for (const auto& nb : c->ordered_connections) {
        if (connected_ids.count(nb->id) || prev_neighbours[c->id].count(nb->id)) continue;
        new_links.emplace_back(c->id, nb->id);
      }
    }
    kf->loop_edges.insert(loop_kf);
    loop_kf->loop_edges.insert(kf);
    loop_kf->not_erase = true;  // loop edges keep both ends (ORB-SLAM2)

    // 4. Essential graph: nodes start at the corrected poses; edges measured on the
    // uncorrected ones (the odometry before the loop), new links on the corrected ones.
    const auto kfs = map_.keyframes();
    std::map<long, Pose> T_wc, T_wc_meas;
    for (const auto& k : kfs) {
      T_wc[k->id] = k->Twc();
      auto it = Tcw_before.find(k->id);
      T_wc_meas[k->id] = it != Tcw_before.end() ? it->second.inverse() : k->Twc();
    }
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
    std::set<long> fixed{loop_kf->id};
    if (map_.origin() && !map_.origin()->bad) fixed.insert(map_.origin()->id);
    const std::map<long, Pose> T_wc_start = T_wc;
    try {
      optimization::optimizePoseGraph(T_wc, edges, fixed, opt_.pose_graph_iterations);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "warning: loop %ld-%ld: essential graph not optimised: %s\n", kf->id,
                   loop_kf->id, e.what());
      T_wc = T_wc_start;
    }

    // 5. Write back: keyframes, then points through the keyframe that last moved them.
    std::unordered_map<long, Pose> T_corr;  // world correction per keyframe: new T_wc * old T_cw
    for (const auto& k : kfs) {
      const Pose& Tn = T_wc[k->id];
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
    kf->not_erase = false;
    last_loop_kf_id_ = kf->id;
    groups_.clear();
    {
      std::lock_guard<std::mutex> lk(queue_mutex_);
      ++loops_closed_;
      loops_.emplace_back(kf->id, loop_kf->id);
    }
  }
  if (mapper_) mapper_->resumeFromLoop();

  if (opt_.global_ba) {
    gba_stop_.store(false);
    gba_running_.store(true);
    const long loop_id = kf->id;
    if (mode_ == RunMode::Sequential) runGlobalBA(loop_id);
    else gba_thread_ = std::thread([this, loop_id] { runGlobalBA(loop_id); });
  }
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
  std::set<long> in_problem_kf;
  std::unordered_map<long, MapPointPtr> point_by_id;
  {
    std::lock_guard<std::mutex> ml(map_.update_mutex);
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
        const size_t i = o.second;
        optimization::BaObservation ob;
        ob.kf_id = k->id;
        ob.point_id = mp->id;
        ob.uv = Eigen::Vector2d(k->f.kps[i].pt.x, k->f.kps[i].pt.y);
        ob.u_right = k->f.right_u[i] >= 0 ? k->f.right_u[i] : -1.0;
        ob.inv_sigma2 = k->f.pyramid->inv_sigma2[k->f.kps[i].octave];
        problem.observations.push_back(ob);
        any = true;
      }
      if (any) {
        problem.points.push_back({mp->id, mp->Xw});
        point_by_id[mp->id] = mp;
      }
    }
  }
  optimization::BaResult res;
  try {
    res = optimization::globalBundleAdjustment(cam_, problem, opt_.global_ba_iterations, gba_stop_);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "warning: global BA after loop at keyframe %ld failed: %s\n", loop_kf_id, e.what());
    gba_running_.store(false);
    return;
  }
  if (res.stopped || gba_stop_.load()) {
    gba_running_.store(false);
    return;
  }
  if (mapper_) {
    mapper_->pauseForLoop();
    mapper_->waitUntilPaused();
  }
  {
    std::lock_guard<std::mutex> ml(map_.update_mutex);
    std::unordered_map<long, Pose> after;
    for (const auto& bk : problem.keyframes)
      if (bk.T_cw.matrix().allFinite()) after[bk.id] = bk.T_cw;
    // Breadth-first over the spanning tree from the origin: keyframes not in the problem
    // follow their parent's correction.
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
    std::lock_guard<std::mutex> lk(queue_mutex_);
    ++gba_done_;
  }
  if (mapper_) mapper_->resumeFromLoop();
  gba_running_.store(false);
}

}  // namespace slam
}  // namespace yolo_slam
