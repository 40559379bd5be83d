#include "yolo_slam/screening/flat_box.h"

#include <algorithm>
#include <random>

namespace yolo_slam {
namespace screening {

namespace {

// Least squares of w = a u + b v + c over the listed points (normal equations; u, v are
// centred for conditioning). False when the points are (nearly) collinear.
bool solvePlane(const std::vector<cv::Point2f>& pts, const std::vector<float>& depths,
                const std::vector<int>& use, InverseDepthPlane& out) {
  if (use.size() < 3) return false;
  double mu = 0, mv = 0;
  for (int i : use) mu += pts[i].x, mv += pts[i].y;
  mu /= use.size();
  mv /= use.size();
  cv::Matx33d A = cv::Matx33d::zeros();
  cv::Vec3d rhs(0, 0, 0);
  for (int i : use) {
    const cv::Vec3d r(pts[i].x - mu, pts[i].y - mv, 1.0);
    const double w = 1.0 / depths[i];
    for (int j = 0; j < 3; ++j) {
      rhs[j] += r[j] * w;
      for (int k = 0; k < 3; ++k) A(j, k) += r[j] * r[k];
    }
  }
  // Collinear pixels leave the (u, v) scatter rank-deficient: no plane is determined.
  const double det_uv = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  const double scale = A(0, 0) + A(1, 1);
  if (!(det_uv > 1e-9 * scale * scale)) return false;
  cv::Vec3d x;
  if (!cv::solve(A, rhs, x, cv::DECOMP_CHOLESKY)) return false;
  out.a = x[0];
  out.b = x[1];
  out.c = x[2] - x[0] * mu - x[1] * mv;
  return true;
}

int countInliers(const std::vector<cv::Point2f>& pts, const std::vector<float>& depths,
                 const InverseDepthPlane& p, double tol, std::vector<int>* in) {
  int n = 0;
  if (in) in->clear();
  for (size_t i = 0; i < pts.size(); ++i) {
    if (p.residual(pts[i], depths[i]) < tol) {
      ++n;
      if (in) in->push_back(static_cast<int>(i));
    }
  }
  return n;
}

}  // namespace

int fitInverseDepthPlane(const std::vector<cv::Point2f>& pts, const std::vector<float>& depths,
                         double tolerance, unsigned seed, InverseDepthPlane& plane,
                         int iterations) {
  const int n = static_cast<int>(pts.size());
  if (n < 3 || depths.size() != pts.size()) return 0;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  int best = 0;
  InverseDepthPlane best_plane;
  std::vector<int> sample(3);
  for (int it = 0; it < iterations; ++it) {
    sample[0] = pick(rng);
    do sample[1] = pick(rng); while (sample[1] == sample[0]);
    do sample[2] = pick(rng); while (sample[2] == sample[0] || sample[2] == sample[1]);
    InverseDepthPlane p;
    if (!solvePlane(pts, depths, sample, p)) continue;
    const int c = countInliers(pts, depths, p, tolerance, nullptr);
    if (c > best) {
      best = c;
      best_plane = p;
      if (best == n) break;
    }
  }
  if (best < 3) return 0;
  // Refine on the inliers twice (the refit can pick up or lose a few borderline points).
  std::vector<int> in;
  for (int r = 0; r < 2; ++r) {
    countInliers(pts, depths, best_plane, tolerance, &in);
    InverseDepthPlane p;
    if (!solvePlane(pts, depths, in, p)) break;
    const int c = countInliers(pts, depths, p, tolerance, nullptr);
    if (c < best) break;
    best = c;
    best_plane = p;
  }
  plane = best_plane;
  return best;
}

FlatBoxResult testFlatBox(const features::FeatureFrame& frame, const cv::Rect2f& box,
                          const std::vector<int>& cluster, const FlatBoxOptions& opt,
                          const std::vector<cv::Rect2f>& exclude) {
  FlatBoxResult res;
  std::vector<cv::Point2f> pts;
  std::vector<float> depths;
  for (int i : cluster) {
    if (frame.depth[i] <= 0) continue;
    pts.push_back(frame.keypoints[i].pt);
    depths.push_back(frame.depth[i]);
  }
  res.cluster_points = static_cast<int>(pts.size());
  if (res.cluster_points < opt.min_points) return res;
  res.cluster_inliers = fitInverseDepthPlane(pts, depths, opt.tolerance, opt.seed, res.plane);
  // A person's cluster is not required to be planar (limbs, relief), but a cluster of which
  // less than half fits one plane is no single static surface.
  if (2 * res.cluster_inliers < res.cluster_points) return res;

  const float dx = static_cast<float>(box.width * opt.ring);
  const float dy = static_cast<float>(box.height * opt.ring);
  const cv::Rect2f outer(box.x - dx, box.y - dy, box.width + 2 * dx, box.height + 2 * dy);
  auto in = [](const cv::Rect2f& r, const cv::Point2f& p) {
    return p.x >= r.x && p.y >= r.y && p.x < r.x + r.width && p.y < r.y + r.height;
  };
  for (size_t i = 0; i < frame.keypoints.size(); ++i) {
    if (frame.depth[i] <= 0) continue;
    const cv::Point2f& p = frame.keypoints[i].pt;
    if (!in(outer, p) || in(box, p)) continue;
    bool other = false;
    for (const cv::Rect2f& e : exclude) other = other || in(e, p);
    if (other) continue;
    ++res.ring_points;
    if (res.plane.residual(p, frame.depth[i]) < opt.tolerance) ++res.ring_on_plane;
  }
  res.flat = res.ring_points >= opt.ring_min_points && res.ringFraction() >= opt.fraction;
  return res;
}

}  // namespace screening
}  // namespace yolo_slam
