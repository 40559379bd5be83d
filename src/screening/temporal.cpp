#include "yolo_slam/screening/temporal.h"

#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/features/match_near.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/screening/screener.h"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace yolo_slam {
namespace screening {

namespace {
// Static pairs used for the camera motion: enough for PnP RANSAC to be stable, few enough to
// keep it near a millisecond.
constexpr int kMaxMotionPairs = 300;
constexpr int kMinMotionInliers = 15;
constexpr double kPnpReprojectionPx = 2.0;
// Flow of a point that the camera motion puts behind the camera: moved, and like no other.
constexpr float kBehindCamera = 1e6f;
// Moved neighbours support a keypoint when their flows differ by at most this share of its flow
// (or motionFlowTolerance pixels if more): limbs and torso of one walker move alike enough.
constexpr double kFlowRelativeTolerance = 0.5;

const std::vector<cv::KeyPoint>& undistorted(const features::FeatureFrame& f) {
  return f.keypoints_un.size() == f.keypoints.size() ? f.keypoints_un : f.keypoints;
}

bool isDynamic(const features::FeatureFrame& f, size_t i) {
  return i < f.dynamic.size() && f.dynamic[i];
}

float depthOf(const features::FeatureFrame& f, size_t i) {
  return i < f.depth.size() ? f.depth[i] : 0.f;
}

// Keypoints of coarser pyramid levels are located less precisely: distances are measured in
// units of the level's scale.
double levelScale(const cv::KeyPoint& kp) { return features::OrbExtractor::levelScale(kp); }

const OptionTable<TemporalOptions>& temporalFields() {
  using O = TemporalOptions;
  static const OptionTable<O> table = {
      {"Screening.propagateLabels", &O::propagate_labels},
      {"Screening.propagateMaxAge", &O::propagate_max_age, Range::atLeast(1)},
      {"Screening.staticBoxVeto", &O::static_box_veto},
      {"Screening.staticBoxFraction", &O::static_box_fraction, Range::fraction()},
      {"Screening.staticBoxMinPoints", &O::static_box_min_points, Range::atLeast(1)},
      {"Screening.staticBoxMaxScore", &O::static_box_max_score, Range::closed(0, 1)},
      {"Screening.temporalRadius", &O::radius_px, Range::positive()},
      {"Screening.temporalMaxHamming", &O::max_hamming, Range::closed(0, 256)},
      {"Screening.temporalMaxDepthChange", &O::max_depth_change_m, Range::positive()},
      {"Screening.temporalStaticTolerance", &O::static_tolerance_px, Range::atLeast(0)},
      {"Screening.motionScreening", &O::motion_screening},
      {"Screening.motionMinResidual", &O::motion_min_residual_px, Range::atLeast(0)},
      {"Screening.motionSupportRadius", &O::motion_support_radius_px, Range::positive()},
      {"Screening.motionMinSupport", &O::motion_min_support, Range::atLeast(0)},
      {"Screening.motionMinShare", &O::motion_min_share, Range::fraction()},
      {"Screening.motionSupportDepth", &O::motion_support_depth_m, Range::positive()},
      {"Screening.motionFlowTolerance", &O::motion_flow_tolerance_px, Range::positive()},
  };
  return table;
}

}  // namespace

TemporalOptions TemporalOptions::load(const Config& cfg) {
  TemporalOptions o;
  readOptions(cfg, o, temporalFields());
  return o;
}

void TemporalOptions::validate(const std::string& where) const {
  checkOptions(*this, where, temporalFields());
}

TemporalScreening::TemporalScreening(const TemporalOptions& options, double box_dilation, double veto_reach)
    : opt_(options), box_dilation_(box_dilation), veto_reach_(veto_reach) {
  opt_.validate();
}

bool TemporalScreening::estimateMotion(const features::FeatureFrame& frame,
                                       const std::vector<int>& match, const CameraModel& cam,
                                       cv::Matx33d& R, cv::Vec3d& t, int& inliers) const {
  std::vector<int> pairs;  // current keypoints whose match is static at both ends, with depth
  for (size_t i = 0; i < match.size(); ++i) {
    const int j = match[i];
    if (j >= 0 && !isDynamic(frame, i) && !isDynamic(prev_, j) && prev_X_[j].z > 0)
      pairs.push_back(static_cast<int>(i));
  }
  if (static_cast<int>(pairs.size()) < kMinMotionInliers) return false;
  const size_t stride = (pairs.size() + kMaxMotionPairs - 1) / kMaxMotionPairs;
  const auto& kun = undistorted(frame);
  std::vector<cv::Point3f> obj;
  std::vector<cv::Point2f> img;
  for (size_t k = 0; k < pairs.size(); k += stride) {
    obj.push_back(prev_X_[match[pairs[k]]]);
    img.push_back(kun[pairs[k]].pt);
  }
  return solveMotion(obj, img, cam, R, t, &inliers);
}

bool TemporalScreening::solveMotion(const std::vector<cv::Point3f>& obj,
                                    const std::vector<cv::Point2f>& img, const CameraModel& cam,
                                    cv::Matx33d& R, cv::Vec3d& t, int* n_inliers) {
  const cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  cv::Mat rvec, tvec;
  std::vector<int> inl;
  // OpenCV's RANSAC seeds its RNG with a constant: the estimate is deterministic.
  const bool ok = cv::solvePnPRansac(obj, img, K, cv::noArray(), rvec, tvec, false, 100,
                                     static_cast<float>(kPnpReprojectionPx), 0.99, inl,
                                     cv::SOLVEPNP_EPNP);
  if (n_inliers) *n_inliers = static_cast<int>(inl.size());
  if (!ok || static_cast<int>(inl.size()) < kMinMotionInliers) return false;
  // EPnP on the minimal sets is coarse; refining on the inliers keeps the static test sharp.
  std::vector<cv::Point3f> o;
  std::vector<cv::Point2f> m;
  for (int k : inl) {
    o.push_back(obj[k]);
    m.push_back(img[k]);
  }
  cv::solvePnPRefineLM(o, m, K, cv::noArray(), rvec, tvec);
  cv::Mat Rm;
  cv::Rodrigues(rvec, Rm);
  R = cv::Matx33d(Rm);
  t = cv::Vec3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  return std::isfinite(cv::norm(R)) && std::isfinite(cv::norm(t));
}

std::vector<int> TemporalScreening::matchPrevious(const features::FeatureFrame& frame, TemporalStats& st) const {
  const size_t n = frame.size();
  std::vector<int> match(n, -1);
  if (frame.descriptors.rows != static_cast<int>(n) || prev_.keypoints.empty()) return match;
  const features::KeypointIndex index(prev_, opt_.radius_px);
  for (size_t i = 0; i < n; ++i) {
    const int j = index.bestMatchNear(frame.keypoints[i].pt, frame.descriptors.ptr<uint8_t>(static_cast<int>(i)),
                                      opt_.radius_px, opt_.max_hamming);
    if (j < 0) continue;
    const float d = depthOf(frame, i), dp = prev_X_[j].z;
    if (d > 0 && dp > 0 && std::fabs(d - dp) > opt_.max_depth_change_m) continue;
    match[i] = j;
    ++st.matched;
  }
  return match;
}

std::vector<int8_t> TemporalScreening::motionVerdicts(const features::FeatureFrame& frame,
                                                      const std::vector<int>& match, const CameraModel& cam,
                                                      const cv::Matx33d& R, const cv::Vec3d& t,
                                                      std::vector<cv::Point2f>& flow, TemporalStats& st) const {
  const size_t n = frame.size();
  std::vector<int8_t> verdict(n, -1);
  flow.assign(n, cv::Point2f(0, 0));
  const auto& kun = undistorted(frame);
  for (size_t i = 0; i < n; ++i) {
    const int j = match[i];
    if (j < 0 || prev_X_[j].z <= 0) continue;
    const cv::Vec3d Y = R * cv::Vec3d(prev_X_[j].x, prev_X_[j].y, prev_X_[j].z) + t;
    bool consistent = false;
    if (Y[2] > 0) {
      flow[i] = kun[i].pt - cv::Point2f(static_cast<float>(cam.fx * Y[0] / Y[2] + cam.cx),
                                        static_cast<float>(cam.fy * Y[1] / Y[2] + cam.cy));
      consistent = cv::norm(flow[i]) <= opt_.static_tolerance_px * levelScale(frame.keypoints[i]);
    } else {
      flow[i] = cv::Point2f(kBehindCamera, kBehindCamera);
    }
    verdict[i] = consistent ? 1 : 0;
    st.static_consistent += consistent ? 1 : 0;
  }
  return verdict;
}

void TemporalScreening::vetoStaticBoxes(features::FeatureFrame& frame, const detection::Boxes& boxes,
                                        const std::vector<int8_t>& verdict, TemporalStats& st) const {
  const size_t n = frame.size();
  std::vector<cv::Rect2f> regions, reach;
  for (const auto& b : boxes) {
    regions.push_back(dilate(b.rect, box_dilation_));
    reach.push_back(dilate(b.rect, box_dilation_ + veto_reach_));
  }
  std::vector<uint8_t> keep_box(regions.size(), 1);  // 1: the box's verdict stands
  for (size_t b = 0; b < regions.size(); ++b) {
    if (boxes[b].score >= opt_.static_box_max_score) continue;
    int tested = 0, consistent = 0;
    for (size_t i = 0; i < n; ++i) {
      if (!frame.dynamic[i] || verdict[i] < 0 || !inside(regions[b], frame.keypoints[i].pt)) continue;
      ++tested;
      consistent += verdict[i];
    }
    if (tested >= opt_.static_box_min_points && consistent >= opt_.static_box_fraction * tested) {
      keep_box[b] = 0;
      ++st.boxes_vetoed;
    }
  }
  if (st.boxes_vetoed == 0) return;
  for (size_t i = 0; i < n; ++i) {
    if (!frame.dynamic[i]) continue;
    bool in_vetoed = false, in_standing = false;
    for (size_t b = 0; b < regions.size(); ++b) {
      if (!inside(reach[b], frame.keypoints[i].pt)) continue;
      (keep_box[b] ? in_standing : in_vetoed) = true;
    }
    // A keypoint also inside a box whose verdict stands (overlapping people) stays dropped.
    if (in_vetoed && !in_standing) {
      frame.dynamic[i] = 0;
      ++st.vetoed;
    }
  }
}

features::FeatureFrame TemporalScreening::staticPositions(const CameraModel& cam, const cv::Matx33d& R,
                                                          const cv::Vec3d& t) const {
  features::FeatureFrame f;
  std::vector<int> rows;
  for (size_t j = 0; j < prev_X_.size(); ++j) {
    if (prev_X_[j].z <= 0) continue;
    const cv::Vec3d Y = R * cv::Vec3d(prev_X_[j].x, prev_X_[j].y, prev_X_[j].z) + t;
    if (Y[2] <= 0) continue;
    cv::KeyPoint kp = prev_.keypoints[j];
    kp.pt = cv::Point2f(static_cast<float>(cam.fx * Y[0] / Y[2] + cam.cx), static_cast<float>(cam.fy * Y[1] / Y[2] + cam.cy));
    f.keypoints.push_back(kp);
    rows.push_back(static_cast<int>(j));
  }
  f.descriptors.create(static_cast<int>(rows.size()), prev_.descriptors.cols, prev_.descriptors.type());
  for (size_t k = 0; k < rows.size(); ++k) prev_.descriptors.row(rows[k]).copyTo(f.descriptors.row(static_cast<int>(k)));
  return f;
}

void TemporalScreening::screenMotion(features::FeatureFrame& frame, const std::vector<int8_t>& verdict,
                                     const std::vector<cv::Point2f>& flow, const CameraModel& cam,
                                     const cv::Matx33d& R, const cv::Vec3d& t, TemporalStats& st) const {
  const size_t n = frame.size();
  // A keypoint that matched a moving twin but also looks like a point of the previous frame that
  // the camera motion brings to where it is, is static: repeated texture (windows, tiles) makes
  // such twins, and the nearest descriptor is not always the right one.
  const features::FeatureFrame statics = staticPositions(cam, R, t);
  const features::KeypointIndex twins(statics, opt_.radius_px);
  const auto& kun = undistorted(frame);
  std::vector<size_t> tested;
  std::vector<uint8_t> moved(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (verdict[i] < 0) continue;
    tested.push_back(i);
    const double scale = levelScale(frame.keypoints[i]);
    moved[i] = verdict[i] == 0 && cv::norm(flow[i]) >= opt_.motion_min_residual_px * scale &&
               twins.bestMatchNear(kun[i].pt, frame.descriptors.ptr<uint8_t>(static_cast<int>(i)),
                                   opt_.motion_min_residual_px * scale, opt_.max_hamming) < 0;
  }
  const float r2 = static_cast<float>(opt_.motion_support_radius_px * opt_.motion_support_radius_px);
  std::vector<size_t> marked;
  for (size_t i : tested) {
    if (!moved[i] || frame.dynamic[i]) continue;
    const cv::Point2f p = frame.keypoints[i].pt;
    const float zi = depthOf(frame, i);
    // A moving body moves its keypoints alike; false matches in the static scene scatter.
    const double flow_tol = std::max(opt_.motion_flow_tolerance_px, kFlowRelativeTolerance * cv::norm(flow[i]));
    int near_tested = 0, near_moved = 0;
    for (size_t k : tested) {
      if (k == i) continue;
      const cv::Point2f d = frame.keypoints[k].pt - p;
      if (d.dot(d) > r2) continue;
      const float zk = depthOf(frame, k);
      if (zi > 0 && zk > 0 && std::fabs(zi - zk) > opt_.motion_support_depth_m) continue;
      ++near_tested;
      near_moved += moved[k] && cv::norm(flow[k] - flow[i]) <= flow_tol ? 1 : 0;
    }
    if (near_moved >= opt_.motion_min_support && near_moved >= opt_.motion_min_share * near_tested)
      marked.push_back(i);
  }
  // Marked after the scan, so that the verdict of one keypoint never depends on the order.
  for (size_t i : marked) frame.dynamic[i] = 1;
  st.motion_dropped += static_cast<int>(marked.size());
}

void TemporalScreening::propagate(features::FeatureFrame& frame, const std::vector<int>& match,
                                  const std::vector<int8_t>& verdict, std::vector<int>& age,
                                  TemporalStats& st) const {
  for (size_t i = 0; i < frame.size(); ++i) {
    const int j = match[i];
    if (verdict[i] != 0 || frame.dynamic[i] || !isDynamic(prev_, j) || prev_age_[j] >= opt_.propagate_max_age)
      continue;
    frame.dynamic[i] = 1;
    age[i] = prev_age_[j] + 1;
    ++st.propagated;
  }
}

void TemporalScreening::remember(const features::FeatureFrame& frame, const CameraModel& cam, std::vector<int> age) {
  const size_t n = frame.size();
  prev_.keypoints = frame.keypoints;
  prev_.descriptors = frame.descriptors.clone();
  prev_.dynamic = frame.dynamic;
  prev_X_.assign(n, cv::Point3f(0, 0, 0));
  const auto& kun = undistorted(frame);
  for (size_t i = 0; i < n; ++i) {
    const float z = depthOf(frame, i);
    if (z > 0)
      prev_X_[i] = cv::Point3f(static_cast<float>((kun[i].pt.x - cam.cx) / cam.fx * z),
                               static_cast<float>((kun[i].pt.y - cam.cy) / cam.fy * z), z);
  }
  prev_age_ = std::move(age);
}

TemporalStats TemporalScreening::apply(features::FeatureFrame& frame, const detection::Boxes& boxes,
                                       const CameraModel& cam) {
  TemporalStats st;
  const size_t n = frame.size();
  frame.dynamic.resize(n, 0);
  std::vector<int> age(n, 0);
  const std::vector<int> match = matchPrevious(frame, st);
  cv::Matx33d R;
  cv::Vec3d t;
  const bool motion_ok = st.matched > 0 && estimateMotion(frame, match, cam, R, t, st.motion_inliers);
  st.motion_frames = motion_ok ? 1 : 0;
  std::vector<int8_t> verdict(n, -1);
  if (motion_ok) {
    std::vector<cv::Point2f> flow;
    verdict = motionVerdicts(frame, match, cam, R, t, flow, st);
    if (opt_.static_box_veto) vetoStaticBoxes(frame, boxes, verdict, st);
    if (opt_.motion_screening) screenMotion(frame, verdict, flow, cam, R, t, st);
    if (opt_.propagate_labels) propagate(frame, match, verdict, age, st);
  }
  frame.motion = verdict;
  remember(frame, cam, std::move(age));
  return st;
}

void TemporalScreening::clear() {
  prev_ = features::FeatureFrame();
  prev_X_.clear();
  prev_age_.clear();
}

TemporalStats& TemporalStats::operator+=(const TemporalStats& o) {
  motion_frames += o.motion_frames;
  motion_inliers += o.motion_inliers;
  matched += o.matched;
  static_consistent += o.static_consistent;
  propagated += o.propagated;
  boxes_vetoed += o.boxes_vetoed;
  vetoed += o.vetoed;
  motion_dropped += o.motion_dropped;
  return *this;
}

void to_json(Json& j, const TemporalStats& s) {
  j = Json{{"matched", s.matched},           {"static_consistent", s.static_consistent},
           {"motion_frames", s.motion_frames}, {"motion_inliers", s.motion_inliers},
           {"propagated", s.propagated},     {"boxes_vetoed", s.boxes_vetoed},
           {"vetoed", s.vetoed},             {"motion_dropped", s.motion_dropped}};
}

}  // namespace screening
}  // namespace yolo_slam
