#include "yolo_slam/screening/temporal.h"

#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/features/match_near.h"
#include "yolo_slam/features/orb_extractor.h"
#include "yolo_slam/screening/screener.h"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>

namespace yolo_slam {
namespace screening {

namespace {
// Static pairs used for the camera motion: enough for PnP RANSAC to be stable, few enough to
// keep it near a millisecond.
constexpr int kMaxMotionPairs = 300;
constexpr int kMinMotionInliers = 15;
constexpr double kPnpReprojectionPx = 2.0;

const std::vector<cv::KeyPoint>& undistorted(const features::FeatureFrame& f) {
  return f.keypoints_un.size() == f.keypoints.size() ? f.keypoints_un : f.keypoints;
}

bool isDynamic(const features::FeatureFrame& f, size_t i) {
  return i < f.dynamic.size() && f.dynamic[i];
}

float depthOf(const features::FeatureFrame& f, size_t i) {
  return i < f.depth.size() ? f.depth[i] : 0.f;
}

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

TemporalScreening::TemporalScreening(const TemporalOptions& options, double box_dilation)
    : opt_(options), box_dilation_(box_dilation) {
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

TemporalStats TemporalScreening::apply(features::FeatureFrame& frame, const detection::Boxes& boxes,
                                       const CameraModel& cam) {
  TemporalStats st;
  const size_t n = frame.size();
  frame.dynamic.resize(n, 0);
  std::vector<int> age(n, 0), match(n, -1);
  const bool usable = frame.descriptors.rows == static_cast<int>(n) && !prev_.keypoints.empty();
  if (usable) {
    const features::KeypointIndex index(prev_, opt_.radius_px);
    for (size_t i = 0; i < n; ++i) {
      const int j = index.bestMatchNear(frame.keypoints[i].pt,
                                        frame.descriptors.ptr<uint8_t>(static_cast<int>(i)),
                                        opt_.radius_px, opt_.max_hamming);
      if (j < 0) continue;
      const float d = depthOf(frame, i), dp = prev_X_[j].z;
      if (d > 0 && dp > 0 && std::fabs(d - dp) > opt_.max_depth_change_m) continue;
      match[i] = j;
      ++st.matched;
    }
  }
  cv::Matx33d R;
  cv::Vec3d t;
  const bool motion_ok = usable && estimateMotion(frame, match, cam, R, t, st.motion_inliers);
  st.motion_frames = motion_ok ? 1 : 0;
  // Per keypoint: -1 untested (no match, or no depth in the previous frame: the point's static
  // position is unknown), 0 moved, 1 static-consistent.
  std::vector<int8_t> verdict(n, -1);
  if (motion_ok) {
    const auto& kun = undistorted(frame);
    for (size_t i = 0; i < n; ++i) {
      const int j = match[i];
      if (j < 0 || prev_X_[j].z <= 0) continue;
      const cv::Vec3d Y = R * cv::Vec3d(prev_X_[j].x, prev_X_[j].y, prev_X_[j].z) + t;
      bool consistent = false;
      if (Y[2] > 0) {
        const double du = cam.fx * Y[0] / Y[2] + cam.cx - kun[i].pt.x;
        const double dv = cam.fy * Y[1] / Y[2] + cam.cy - kun[i].pt.y;
        // Keypoints of coarser pyramid levels are located less precisely: the tolerance grows
        // with the level's scale (the keypoint's size is the patch diameter times the scale).
        const double scale =
            std::max(1.0, frame.keypoints[i].size / double(features::OrbExtractor::kPatchSize));
        const double tol = opt_.static_tolerance_px * scale;
        consistent = du * du + dv * dv <= tol * tol;
      }
      verdict[i] = consistent ? 1 : 0;
      st.static_consistent += consistent ? 1 : 0;
    }
  }
  if (motion_ok && opt_.static_box_veto) {
    std::vector<cv::Rect2f> regions;
    for (const auto& b : boxes) regions.push_back(dilate(b.rect, box_dilation_));
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
    if (st.boxes_vetoed > 0) {
      for (size_t i = 0; i < n; ++i) {
        if (!frame.dynamic[i]) continue;
        bool in_vetoed = false, in_standing = false;
        for (size_t b = 0; b < regions.size(); ++b) {
          if (!inside(regions[b], frame.keypoints[i].pt)) continue;
          (keep_box[b] ? in_standing : in_vetoed) = true;
        }
        // A keypoint also inside a box whose verdict stands (overlapping people) stays dropped.
        if (in_vetoed && !in_standing) {
          frame.dynamic[i] = 0;
          ++st.vetoed;
        }
      }
    }
  }
  if (motion_ok && opt_.propagate_labels) {
    for (size_t i = 0; i < n; ++i) {
      const int j = match[i];
      if (verdict[i] != 0 || frame.dynamic[i] || !isDynamic(prev_, j) || prev_age_[j] >= opt_.propagate_max_age)
        continue;
      frame.dynamic[i] = 1;
      age[i] = prev_age_[j] + 1;
      ++st.propagated;
    }
  }
  frame.motion = verdict;
  // This frame becomes the previous one.
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
  return *this;
}

void to_json(Json& j, const TemporalStats& s) {
  j = Json{{"matched", s.matched},           {"static_consistent", s.static_consistent},
           {"motion_frames", s.motion_frames}, {"motion_inliers", s.motion_inliers},
           {"propagated", s.propagated},     {"boxes_vetoed", s.boxes_vetoed},
           {"vetoed", s.vetoed}};
}

}  // namespace screening
}  // namespace yolo_slam
