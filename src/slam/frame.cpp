#include "yolo_slam/slam/frame.h"

#include "yolo_slam/vocabulary/vocabulary.h"

#include <algorithm>
#include <cmath>

namespace yolo_slam {
namespace slam {

ScalePyramid ScalePyramid::make(int n_levels, double scale_factor) {
  ScalePyramid p;
  p.n_levels = std::max(1, n_levels);
  p.scale_factor = scale_factor;
  p.log_scale_factor = std::log(scale_factor);
  p.scale.resize(p.n_levels);
  p.inv_scale.resize(p.n_levels);
  p.sigma2.resize(p.n_levels);
  p.inv_sigma2.resize(p.n_levels);
  double s = 1.0;
  for (int i = 0; i < p.n_levels; ++i) {
    p.scale[i] = s;
    p.inv_scale[i] = 1.0 / s;
    p.sigma2[i] = s * s;
    p.inv_sigma2[i] = 1.0 / (s * s);
    s *= scale_factor;
  }
  return p;
}

FrameGeometry FrameGeometry::make(const CameraModel& cam) {
  FrameGeometry g;
  g.min_x = 0;
  g.max_x = cam.width;
  g.min_y = 0;
  g.max_y = cam.height;
  if (cam.hasDistortion()) {
    // Bounds of the undistorted image (ORB-SLAM2 ComputeImageBounds).
    std::vector<cv::Point2f> c = {{0.f, 0.f},
                                  {static_cast<float>(cam.width), 0.f},
                                  {0.f, static_cast<float>(cam.height)},
                                  {static_cast<float>(cam.width), static_cast<float>(cam.height)}};
    c = cam.undistort(c);
    g.min_x = std::min(c[0].x, c[2].x);
    g.max_x = std::max(c[1].x, c[3].x);
    g.min_y = std::min(c[0].y, c[1].y);
    g.max_y = std::max(c[2].y, c[3].y);
  }
  g.inv_cell_w = kGridCols / (g.max_x - g.min_x);
  g.inv_cell_h = kGridRows / (g.max_y - g.min_y);
  return g;
}

Frame::Frame(const features::FeatureFrame& ff, const CameraModel& camera, const FrameGeometry& g,
             std::shared_ptr<const ScalePyramid> pyr, long frame_id)
    : id(frame_id), stamp(ff.stamp), cam(camera), geom(g), pyramid(std::move(pyr)) {
  kps = ff.keypoints_un.size() == ff.keypoints.size() ? ff.keypoints_un : ff.keypoints;
  N = static_cast<int>(kps.size());
  descriptors = ff.descriptors;
  if (descriptors.rows != N || (N > 0 && (descriptors.cols != 32 || descriptors.type() != CV_8U))) {
    // Inconsistent input cannot be matched; treat it as a frame without features.
    N = 0;
    kps.clear();
    descriptors = cv::Mat(0, 32, CV_8U);
  }
  depth.assign(N, -1.f);
  right_u.assign(N, -1.f);
  dynamic.assign(N, 0);
  if (ff.motion.size() == static_cast<size_t>(N)) motion.assign(ff.motion.begin(), ff.motion.end());
  else motion.clear();
  if (ff.boxed.size() == static_cast<size_t>(N)) boxed.assign(ff.boxed.begin(), ff.boxed.end());
  else boxed.clear();
  for (int i = 0; i < N; ++i) {
    if (static_cast<size_t>(i) < ff.depth.size()) {
      float d = ff.depth[i];
      if (std::isfinite(d) && d > 0) depth[i] = d;
    }
    if (static_cast<size_t>(i) < ff.right_u.size() && depth[i] > 0) {
      float r = ff.right_u[i];
      right_u[i] = std::isfinite(r) ? r : -1.f;
    }
    if (static_cast<size_t>(i) < ff.dynamic.size()) dynamic[i] = ff.dynamic[i];
    // Octaves beyond the pyramid (foreign extractor settings) are clamped.
    kps[i].octave = std::max(0, std::min(kps[i].octave, pyramid->n_levels - 1));
  }
  points.assign(N, nullptr);
  outlier.assign(N, false);

  grid_.assign(FrameGeometry::kGridCols * FrameGeometry::kGridRows, {});
  for (int i = 0; i < N; ++i) {
    const auto& kp = kps[i];
    int gx = static_cast<int>(std::round((kp.pt.x - geom.min_x) * geom.inv_cell_w));
    int gy = static_cast<int>(std::round((kp.pt.y - geom.min_y) * geom.inv_cell_h));
    if (gx < 0 || gx >= FrameGeometry::kGridCols || gy < 0 || gy >= FrameGeometry::kGridRows) continue;
    grid_[gy * FrameGeometry::kGridCols + gx].push_back(static_cast<uint32_t>(i));
  }
}

std::vector<size_t> Frame::featuresInArea(double x, double y, double r, int min_level,
                                          int max_level, bool dynamic_only) const {
  std::vector<size_t> out;
  featuresInArea(out, x, y, r, min_level, max_level, dynamic_only);
  return out;
}

void Frame::featuresInArea(std::vector<size_t>& out, double x, double y, double r, int min_level,
                           int max_level, bool dynamic_only) const {
  out.clear();
  if (grid_.empty() || !std::isfinite(x) || !std::isfinite(y)) return;
  const int c0 = std::max(0, static_cast<int>(std::floor((x - geom.min_x - r) * geom.inv_cell_w)));
  const int c1 = std::min(FrameGeometry::kGridCols - 1,
                          static_cast<int>(std::ceil((x - geom.min_x + r) * geom.inv_cell_w)));
  const int r0 = std::max(0, static_cast<int>(std::floor((y - geom.min_y - r) * geom.inv_cell_h)));
  const int r1 = std::min(FrameGeometry::kGridRows - 1,
                          static_cast<int>(std::ceil((y - geom.min_y + r) * geom.inv_cell_h)));
  if (c0 >= FrameGeometry::kGridCols || c1 < 0 || r0 >= FrameGeometry::kGridRows || r1 < 0) return;
  const bool check_levels = min_level > 0 || max_level >= 0;
  for (int gy = r0; gy <= r1; ++gy) {
    for (int gx = c0; gx <= c1; ++gx) {
      for (uint32_t i : grid_[gy * FrameGeometry::kGridCols + gx]) {
        if ((dynamic[i] != 0) != dynamic_only) continue;
        const auto& kp = kps[i];
        if (check_levels) {
          if (kp.octave < min_level) continue;
          if (max_level >= 0 && kp.octave > max_level) continue;
        }
        const double dx = kp.pt.x - x, dy = kp.pt.y - y;
        if (std::fabs(dx) < r && std::fabs(dy) < r) out.push_back(i);
      }
    }
  }
}

bool Frame::unprojectWorld(size_t i, Eigen::Vector3d& Xw) const {
  if (i >= static_cast<size_t>(N) || depth[i] <= 0) return false;
  Eigen::Vector3d pc = cam.unproject(kps[i].pt.x, kps[i].pt.y, depth[i]);
  Xw = T_cw.inverse() * pc;
  return Xw.allFinite();
}

int Frame::countWithDepth() const {
  int n = 0;
  for (int i = 0; i < N; ++i) n += (depth[i] > 0 && !dynamic[i]) ? 1 : 0;
  return n;
}

bool Frame::seenMoving(int i) const {
  if (testedMoving(i)) return true;
  return !boxed.empty() && boxed[i] && !staticConsistent(i);
}

std::vector<std::pair<float, int>> Frame::staticByDepth() const {
  std::vector<std::pair<float, int>> out;
  for (int i = 0; i < N; ++i)
    if (depth[i] > 0 && !dynamic[i]) out.emplace_back(depth[i], i);
  std::sort(out.begin(), out.end());
  return out;
}

void computeBow(const vocabulary::Vocabulary* voc, Frame& F) {
  if (!voc || !F.bow.empty() || F.N == 0) return;
  std::vector<int> rows;  // the static keypoints
  rows.reserve(F.N);
  for (int i = 0; i < F.N; ++i)
    if (i >= static_cast<int>(F.dynamic.size()) || !F.dynamic[i]) rows.push_back(i);
  if (static_cast<int>(rows.size()) == F.N) {
    voc->transform(F.descriptors, F.bow.bow, F.bow.features, kBowLevelsUp);
    return;
  }
  if (rows.empty()) return;
  cv::Mat desc(static_cast<int>(rows.size()), F.descriptors.cols, F.descriptors.type());
  for (size_t k = 0; k < rows.size(); ++k) F.descriptors.row(rows[k]).copyTo(desc.row(static_cast<int>(k)));
  voc->transform(desc, F.bow.bow, F.bow.features, kBowLevelsUp);
  for (auto& node : F.bow.features)
    for (unsigned& idx : node.second) idx = static_cast<unsigned>(rows[idx]);
}

void Frame::releaseFeatures() {
  N = 0;
  std::vector<cv::KeyPoint>().swap(kps);
  descriptors.release();
  std::vector<float>().swap(depth);
  std::vector<float>().swap(right_u);
  std::vector<uint8_t>().swap(dynamic);
  std::vector<int8_t>().swap(motion);
  std::vector<uint8_t>().swap(boxed);
  std::vector<MapPointPtr>().swap(points);
  std::vector<bool>().swap(outlier);
  bow = BowData();
  std::vector<std::vector<uint32_t>>().swap(grid_);
}

}  // namespace slam
}  // namespace yolo_slam
