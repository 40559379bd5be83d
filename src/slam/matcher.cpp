#include "yolo_slam/slam/matcher.h"

#include "yolo_slam/features/hamming.h"
#include "yolo_slam/features/rotation_histogram.h"
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_point.h"
#include "yolo_slam/vocabulary/bow_matcher.h"

#include <algorithm>
#include <cmath>

namespace yolo_slam {
namespace slam {
namespace matcher {

namespace {

// ORB-SLAM2 ORBmatcher values.
constexpr int kNoMatch = 256;               // above any Hamming distance of 256-bit descriptors
constexpr double kMinDistFactor = 0.8;      // isInFrustum: scale-invariance range margins
constexpr double kMaxDistFactor = 1.2;
constexpr double kFrontalViewCos = 0.998;   // RadiusByViewingCos: window x 2.5 when this frontal,
constexpr double kFrontalWindow = 2.5;      // else x 4
constexpr double kObliqueWindow = 4.0;
constexpr double kChi2Epipolar = 3.84;      // SearchForTriangulation: chi2(1 dof, 95%)
constexpr double kMinEpipoleDist2 = 100;    // ... min squared distance to the epipole (x scale)
constexpr double kChi2FuseMono = 5.99;      // Fuse: chi2(2 dof, 95%) and 3 dof (7.8)
constexpr double kChi2FuseStereo = 7.8;
constexpr double kFuseViewCos = 0.5;        // Fuse: at most 60 deg from the mean viewing direction

inline int dist(const cv::Mat& d, int row, const cv::Mat& d2, int row2) {
  return features::hammingDistance(d.ptr<uint8_t>(row), d2.ptr<uint8_t>(row2));
}
inline int dist(const cv::Mat& mp_desc, const cv::Mat& d, int row) {
  return features::hammingDistance(mp_desc.ptr<uint8_t>(), d.ptr<uint8_t>(row));
}

}  // namespace

bool projectInFrame(const Frame& F, const MapPointPtr& mp, double min_view_cos, Projection& out) {
  if (!mp || mp->bad) return false;
  const Eigen::Vector3d pc = F.T_cw * mp->Xw;
  if (!(pc.z() > 0)) return false;
  const Eigen::Vector2d uv = F.cam.project(pc);
  if (F.geom.outside(uv)) return false;
  const Eigen::Vector3d PO = mp->Xw - F.cameraCenter();
  const double d = PO.norm();
  if (d < kMinDistFactor * mp->min_dist || d > kMaxDistFactor * mp->max_dist) return false;
  const double view_cos = PO.dot(mp->normal) / d;
  if (view_cos < min_view_cos) return false;
  out.mp = mp;
  out.u = uv.x();
  out.v = uv.y();
  out.ur = uv.x() - F.cam.bf / pc.z();
  out.z = pc.z();
  out.level = mp->predictScale(d, F.pyramid->n_levels, F.pyramid->log_scale_factor);
  out.view_cos = view_cos;
  return true;
}

int searchLastFrame(Frame& F, const Frame& last, double th) {
  int n = 0;
  features::RotationHistogram hist;
  std::vector<size_t> cand;
  const Pose T_lc = last.T_cw * F.T_cw.inverse();
  const double tz = T_lc.inverse().translation().z();  // ORB-SLAM2 tlc(2)
  const double b = F.cam.baseline();
  const bool forward = tz > b, backward = -tz > b;
  const auto& pyr = *F.pyramid;
  for (int i = 0; i < last.N; ++i) {
    const MapPointPtr& mp = last.points[i];
    if (!mp || mp->bad || last.outlier[i] || mp->dynamic) continue;
    const Eigen::Vector3d pc = F.T_cw * mp->Xw;
    if (!(pc.z() > 0)) continue;
    const Eigen::Vector2d uv = F.cam.project(pc);
    if (F.geom.outside(uv)) continue;
    const int oct = last.kps[i].octave;
    const double radius = th * pyr.scale[oct];
    if (forward) F.featuresInArea(cand, uv.x(), uv.y(), radius, oct);
    else if (backward) F.featuresInArea(cand, uv.x(), uv.y(), radius, 0, oct);
    else F.featuresInArea(cand, uv.x(), uv.y(), radius, oct - 1, oct + 1);
    if (cand.empty() || mp->descriptor.empty()) continue;
    const double ur = uv.x() - F.cam.bf / pc.z();
    int best = kNoMatch;
    int best_idx = -1;
    for (size_t j : cand) {
      const MapPointPtr& cur = F.points[j];
      if (cur && cur->numObservations() > 0) continue;
      if (F.right_u[j] > 0 && std::fabs(ur - F.right_u[j]) > radius) continue;
      int d = dist(mp->descriptor, F.descriptors, static_cast<int>(j));
      if (d < best) {
        best = d;
        best_idx = static_cast<int>(j);
      }
    }
    if (best <= kThHigh && best_idx >= 0) {
      F.points[best_idx] = mp;
      ++n;
      hist.add(last.kps[i].angle, F.kps[best_idx].angle, best_idx);
    }
  }
  for (size_t idx : hist.outliers()) {
    F.points[idx].reset();
    --n;
  }
  return n;
}

namespace {

// The best dynamic keypoints near a projection: one the frame-to-frame test saw move (or any,
// when it did not run), and one it did not (for DroppedMatching), each at the point's depth.
struct DynamicCandidates {
  int moved = kNoMatch;
  int unmoved = kNoMatch, unmoved2 = kNoMatch, unmoved_idx = -1;
};

// `cand` is the caller's buffer, reused across calls.
DynamicCandidates dynamicCandidates(const Frame& F, const Projection& p, double r,
                                    std::vector<size_t>& cand) {
  DynamicCandidates c;
  F.featuresInArea(cand, p.u, p.v, r, p.level - 1, p.level, true);
  for (size_t j : cand) {
    if (p.z > 0 && F.depth[j] > 0 && std::fabs(F.depth[j] - p.z) > kDynamicDepthTolerance * p.z) continue;
    const int d = dist(p.mp->descriptor, F.descriptors, static_cast<int>(j));
    // When the frame-to-frame test ran, only a keypoint it saw move counts as a hit: static
    // background that screening dropped inside a person's box matches its own map point
    // perfectly, and marking it erased the map behind every passing person (ATE on the
    // walking presets 6.8-20.9 mm with that, 3.9-11 mm without; docs/ablation.md).
    if (F.motion.empty() || F.motion[j] == 0) {
      c.moved = std::min(c.moved, d);
    } else if (!F.points[j]) {
      if (d < c.unmoved) {
        c.unmoved2 = c.unmoved;
        c.unmoved = d;
        c.unmoved_idx = static_cast<int>(j);
      } else if (d < c.unmoved2) {
        c.unmoved2 = d;
      }
    }
  }
  return c;
}

}  // namespace

int searchProjections(Frame& F, const std::vector<Projection>& proj, double th, double nn_ratio,
                      std::vector<MapPointPtr>* dynamic_hits, const DroppedMatching* dropped) {
  int n = 0;
  const auto& pyr = *F.pyramid;
  const bool match_dropped = dropped && dropped->min_observations > 0 && !F.motion.empty();
  std::vector<size_t> cand, dynamic_cand;
  for (const Projection& p : proj) {
    const MapPointPtr& mp = p.mp;
    if (!mp || mp->bad || mp->descriptor.empty()) continue;
    const double r = (p.view_cos > kFrontalViewCos ? kFrontalWindow : kObliqueWindow) * th * pyr.scale[p.level];
    F.featuresInArea(cand, p.u, p.v, r, p.level - 1, p.level);
    int best = kNoMatch, best2 = kNoMatch, best_level = -1, best_level2 = -1, best_idx = -1;
    for (size_t j : cand) {
      const MapPointPtr& cur = F.points[j];
      if (cur && cur->numObservations() > 0) continue;
      if (F.right_u[j] > 0 && std::fabs(p.ur - F.right_u[j]) > r) continue;
      int d = dist(mp->descriptor, F.descriptors, static_cast<int>(j));
      if (d < best) {
        best2 = best;
        best_level2 = best_level;
        best = d;
        best_level = F.kps[j].octave;
        best_idx = static_cast<int>(j);
      } else if (d < best2) {
        best_level2 = F.kps[j].octave;
        best2 = d;
      }
    }
    DynamicCandidates dyn;
    if (dynamic_hits || match_dropped) dyn = dynamicCandidates(F, p, r, dynamic_cand);
    // A point that now projects onto a moving keypoint with a better descriptor match than any
    // static one sits on a moving object, if that keypoint is at the point's depth (a nearer
    // one is a person walking in front of the point: hidden, not moving).
    if (dynamic_hits && dyn.moved <= kThLow && dyn.moved < best) {
      dynamic_hits->push_back(mp);
      continue;
    }
    if (best <= kThHigh && best_idx >= 0) {
      if (best_level == best_level2 && best > nn_ratio * best2) continue;
      F.points[best_idx] = mp;
      ++n;
      continue;
    }
    if (match_dropped && dyn.unmoved <= kThLow && dyn.unmoved < nn_ratio * std::min(dyn.unmoved2, best) &&
        mp->numObservations() >= dropped->min_observations) {
      F.points[dyn.unmoved_idx] = mp;
      F.dynamic[dyn.unmoved_idx] = 0;
      if (dropped->matched) dropped->matched->push_back(dyn.unmoved_idx);
      ++n;
    }
  }
  return n;
}

int searchByBow(const KeyFrame& kf, Frame& F, double nn_ratio) {
  std::vector<uint8_t> kf_usable(static_cast<size_t>(kf.f.descriptors.rows), 0);
  for (size_t i = 0; i < kf_usable.size() && i < kf.f.points.size(); ++i) {
    const MapPointPtr& mp = kf.f.points[i];
    kf_usable[i] = mp && !mp->bad && !mp->dynamic;
  }
  std::vector<uint8_t> f_usable(static_cast<size_t>(F.descriptors.rows), 0);
  for (size_t i = 0; i < f_usable.size() && i < F.dynamic.size(); ++i) f_usable[i] = !F.dynamic[i];
  const vocabulary::BowSide a{&kf.f.bow.features, &kf.f.descriptors, &kf.f.kps, &kf_usable};
  const vocabulary::BowSide b{&F.bow.features, &F.descriptors, &F.kps, &f_usable};
  vocabulary::BowMatchOptions opt;
  opt.th_low = kThLow;
  opt.nn_ratio = static_cast<float>(nn_ratio);
  const std::vector<vocabulary::BowMatch> matches = vocabulary::searchByBow(a, b, opt);
  for (const vocabulary::BowMatch& m : matches) F.points[m.b] = kf.f.points[m.a];
  return static_cast<int>(matches.size());
}

std::vector<std::pair<size_t, size_t>> searchForTriangulation(const KeyFrame& kf1,
                                                              const KeyFrame& kf2,
                                                              const Eigen::Matrix3d& F12) {
  // Epipole of camera 1 in image 2: candidates too close to it are ambiguous.
  const Eigen::Vector3d C1_in_2 = kf2.Tcw() * kf1.center();
  const auto& pyr = *kf1.f.pyramid;
  Eigen::Vector2d ep(-1e9, -1e9);
  if (C1_in_2.z() > 1e-9) ep = kf2.f.cam.project(C1_in_2);

  std::vector<int> free2;
  for (int j = 0; j < kf2.f.N; ++j)
    if (!kf2.f.points[j] && !kf2.f.dynamic[j]) free2.push_back(j);
  std::vector<int> match12(kf1.f.N, -1);
  std::vector<int> best_for2(kf2.f.N, kNoMatch);
  std::vector<int> owner2(kf2.f.N, -1);
  for (int i = 0; i < kf1.f.N; ++i) {
    if (kf1.f.points[i] || kf1.f.dynamic[i]) continue;
    const cv::KeyPoint& k1 = kf1.f.kps[i];
    const bool stereo1 = kf1.f.right_u[i] >= 0;
    // Epipolar line of x1 in image 2 (x2^T F12 x1 = 0): l = F12 x1.
    const Eigen::Vector3d l = F12 * Eigen::Vector3d(k1.pt.x, k1.pt.y, 1.0);
    const double ln = l.head<2>().squaredNorm();
    if (ln < 1e-18) continue;
    int best = kThLow + 1, best_idx = -1;
    for (int j : free2) {
      const cv::KeyPoint& k2 = kf2.f.kps[j];
      const bool stereo2 = kf2.f.right_u[j] >= 0;
      const double num = l.x() * k2.pt.x + l.y() * k2.pt.y + l.z();
      const double d2 = num * num / ln;
      if (d2 >= kChi2Epipolar * pyr.sigma2[k2.octave]) continue;
      const int d = dist(kf1.f.descriptors, i, kf2.f.descriptors, j);
      if (d >= best) continue;
      if (!stereo1 && !stereo2) {
        const double ex = ep.x() - k2.pt.x, ey = ep.y() - k2.pt.y;
        if (ex * ex + ey * ey < kMinEpipoleDist2 * pyr.scale[k2.octave]) continue;
      }
      best = d;
      best_idx = j;
    }
    if (best_idx >= 0 && best < best_for2[best_idx]) {
      if (owner2[best_idx] >= 0) match12[owner2[best_idx]] = -1;
      owner2[best_idx] = i;
      best_for2[best_idx] = best;
      match12[i] = best_idx;
    }
  }
  features::RotationHistogram hist;
  for (int i = 0; i < kf1.f.N; ++i)
    if (match12[i] >= 0) hist.add(kf1.f.kps[i].angle, kf2.f.kps[match12[i]].angle, i);
  for (size_t i : hist.outliers()) match12[i] = -1;
  std::vector<std::pair<size_t, size_t>> out;
  for (int i = 0; i < kf1.f.N; ++i)
    if (match12[i] >= 0) out.emplace_back(i, match12[i]);
  return out;
}

int fuse(Map& map, const KeyFramePtr& kf, const std::vector<MapPointPtr>& points, double th) {
  int n = 0;
  const Frame& F = kf->f;
  const auto& pyr = *F.pyramid;
  const Eigen::Vector3d Ow = kf->center();
  for (const MapPointPtr& mp0 : points) {
    MapPointPtr mp = mp0;
    if (!mp || mp->bad || mp->descriptor.empty() || mp->inKeyFrame(kf.get())) continue;
    const Eigen::Vector3d pc = F.T_cw * mp->Xw;
    if (!(pc.z() > 0)) continue;
    const Eigen::Vector2d uv = F.cam.project(pc);
    if (F.geom.outside(uv)) continue;
    const double ur = uv.x() - F.cam.bf / pc.z();
    const Eigen::Vector3d PO = mp->Xw - Ow;
    const double d = PO.norm();
    if (d < kMinDistFactor * mp->min_dist || d > kMaxDistFactor * mp->max_dist) continue;
    if (PO.dot(mp->normal) < kFuseViewCos * d) continue;
    const int level = mp->predictScale(d, pyr.n_levels, pyr.log_scale_factor);
    const double radius = th * pyr.scale[level];
    int best = kNoMatch, best_idx = -1;
    for (size_t j : F.featuresInArea(uv.x(), uv.y(), radius)) {
      const cv::KeyPoint& kp = F.kps[j];
      if (kp.octave < level - 1 || kp.octave > level) continue;
      const double ex = uv.x() - kp.pt.x, ey = uv.y() - kp.pt.y;
      double e2 = ex * ex + ey * ey;
      double chi = kChi2FuseMono;
      if (F.right_u[j] >= 0) {
        const double er = ur - F.right_u[j];
        e2 += er * er;
        chi = kChi2FuseStereo;
      }
      if (e2 * pyr.inv_sigma2[kp.octave] > chi) continue;
      const int dd = dist(mp->descriptor, F.descriptors, static_cast<int>(j));
      if (dd < best) {
        best = dd;
        best_idx = static_cast<int>(j);
      }
    }
    if (best_idx < 0 || best > kThLow) continue;
    MapPointPtr in_kf = F.points[best_idx];
    if (in_kf && !in_kf->bad) {
      if (in_kf->numObservations() > mp->numObservations()) map.replaceMapPoint(mp, in_kf);
      else map.replaceMapPoint(in_kf, mp);
    } else {
      Map::addObservation(mp, kf, best_idx);
    }
    ++n;
  }
  return n;
}

}  // namespace matcher
}  // namespace slam
}  // namespace yolo_slam
