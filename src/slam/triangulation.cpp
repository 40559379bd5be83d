#include "yolo_slam/slam/triangulation.h"

#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/keyframe.h"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace yolo_slam {
namespace slam {

namespace {

// ORB-SLAM2 CreateNewMapPoints: distance ratio against octave ratio tolerance (x scale factor),
// rays more parallel than this cosine are not triangulated without depth, chi2 bounds of the
// reprojection (2 dof 95%, and ORB-SLAM2's 7.8 for 3 dof).
constexpr double kScaleConsistency = 1.5;
constexpr double kMaxParallaxCos = 0.9998;
constexpr double kTriangulationChi2Mono = 5.991;
constexpr double kTriangulationChi2Stereo = 7.8;

// Linear (DLT) triangulation of two normalised image points.
bool triangulate(const Eigen::Vector3d& xn1, const Eigen::Vector3d& xn2, const Pose& T1,
                 const Pose& T2, Eigen::Vector3d& X) {
  Eigen::Matrix<double, 3, 4> P1 = T1.matrix().topRows<3>(), P2 = T2.matrix().topRows<3>();
  Eigen::Matrix4d A;
  A.row(0) = xn1.x() * P1.row(2) - P1.row(0);
  A.row(1) = xn1.y() * P1.row(2) - P1.row(1);
  A.row(2) = xn2.x() * P2.row(2) - P2.row(0);
  A.row(3) = xn2.y() * P2.row(2) - P2.row(1);
  Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  Eigen::Vector4d h = svd.matrixV().col(3);
  if (std::fabs(h(3)) < 1e-12) return false;
  X = h.head<3>() / h(3);
  return X.allFinite();
}

double nearDepth(const Frame& f) {
  std::vector<float> d;
  d.reserve(f.depth.size());
  for (size_t i = 0; i < f.depth.size(); ++i)
    if (f.depth[i] > 0 && !f.dynamic[i]) d.push_back(f.depth[i]);
  if (d.empty()) return 0;
  const size_t k = static_cast<size_t>(kNearDepthQuantile * static_cast<double>(d.size() - 1));
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(k), d.end());
  return d[k];
}

// A new point's reprojection in a keyframe is within the chi2 bound of its octave.
bool reprojectionOk(const CameraModel& cam, const ScalePyramid& pyr, const Eigen::Vector3d& pc,
                    const cv::KeyPoint& kp, double ur, bool stereo) {
  const Eigen::Vector2d uv = cam.project(pc);
  const double ex = uv.x() - kp.pt.x, ey = uv.y() - kp.pt.y;
  const double s2 = pyr.sigma2[kp.octave];
  if (!stereo) return ex * ex + ey * ey <= kTriangulationChi2Mono * s2;
  const double er = uv.x() - cam.bf / pc.z() - ur;
  return ex * ex + ey * ey + er * er <= kTriangulationChi2Stereo * s2;
}

Eigen::Vector3d normalised(const CameraModel& cam, const cv::KeyPoint& kp) {
  return {(kp.pt.x - cam.cx) / cam.fx, (kp.pt.y - cam.cy) / cam.fy, 1.0};
}

// The point of the match before any check: triangulated when the rays' parallax beats the
// depth's (and, without depth, the rays are not nearly parallel), else back-projected from the
// depth with the wider parallax.
bool pointOfMatch(const CameraModel& cam, const TriangulationView& v1, const TriangulationView& v2,
                  size_t i1, size_t i2, Eigen::Vector3d& X) {
  const Frame& f1 = v1.kf.f;
  const Frame& f2 = v2.kf.f;
  const bool stereo1 = f1.right_u[i1] >= 0, stereo2 = f2.right_u[i2] >= 0;
  const Eigen::Vector3d xn1 = normalised(cam, f1.kps[i1]), xn2 = normalised(cam, f2.kps[i2]);
  const Eigen::Vector3d ray1 = v1.R_wc * xn1, ray2 = v2.R_wc * xn2;
  const double cos_rays = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
  const double b = cam.baseline();
  const double cos_st1 = stereo1 ? std::cos(2 * std::atan2(b / 2, f1.depth[i1])) : 2.0;
  const double cos_st2 = stereo2 ? std::cos(2 * std::atan2(b / 2, f2.depth[i2])) : 2.0;
  const double cos_st = std::min(cos_st1, cos_st2);
  if (cos_rays < cos_st && cos_rays > 0 && (stereo1 || stereo2 || cos_rays < kMaxParallaxCos))
    return triangulate(xn1, xn2, v1.T, v2.T, X);
  if (stereo1 && cos_st1 < cos_st2) return f1.unprojectWorld(i1, X);
  if (stereo2 && cos_st2 < cos_st1) return f2.unprojectWorld(i2, X);
  return false;
}

// The distance ratio of the point from the two cameras agrees with the keypoints' octaves.
bool scaleConsistent(const TriangulationView& v1, const TriangulationView& v2, size_t i1,
                     size_t i2, const Eigen::Vector3d& X) {
  const ScalePyramid& pyr = *v1.kf.f.pyramid;
  const double d1 = (X - v1.O).norm(), d2 = (X - v2.O).norm();
  if (d1 == 0 || d2 == 0) return false;
  const double ratio_factor = kScaleConsistency * pyr.scale_factor;
  const double ratio_dist = d2 / d1;
  const double ratio_oct = pyr.scale[v1.kf.f.kps[i1].octave] / pyr.scale[v2.kf.f.kps[i2].octave];
  return !(ratio_dist * ratio_factor < ratio_oct || ratio_dist > ratio_oct * ratio_factor);
}

}  // namespace

TriangulationView::TriangulationView(const KeyFrame& keyframe)
    : kf(keyframe),
      T(keyframe.Tcw()),
      O(keyframe.center()),
      R_wc(T.linear().transpose()),
      near_depth(nearDepth(keyframe.f)) {}

bool outsideMeasuredFreeSpace(const TriangulationView& v, size_t i, double z,
                              double free_space_ratio) {
  const Frame& f = v.kf.f;
  if (f.depth[i] > 0 || free_space_ratio <= 0) return true;
  const cv::Point2f& pt = f.kps[i].pt;
  size_t measured = 0;
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t j : f.featuresInArea(pt.x, pt.y, kFreeSpaceRadius)) {
    if (f.depth[j] <= 0) continue;
    ++measured;
    nearest = std::min(nearest, static_cast<double>(f.depth[j]));
  }
  if (measured < kFreeSpaceMinNeighbours) nearest = v.near_depth;
  return z >= free_space_ratio * nearest;
}

bool triangulateMatch(const CameraModel& cam, const TriangulationView& v1,
                      const TriangulationView& v2, size_t i1, size_t i2, double free_space_ratio,
                      Eigen::Vector3d& X) {
  if (!pointOfMatch(cam, v1, v2, i1, i2, X)) return false;
  const Frame& f1 = v1.kf.f;
  const Frame& f2 = v2.kf.f;
  const Eigen::Vector3d p1 = v1.T * X, p2 = v2.T * X;
  if (p1.z() <= 0 || p2.z() <= 0) return false;
  if (!outsideMeasuredFreeSpace(v1, i1, p1.z(), free_space_ratio) ||
      !outsideMeasuredFreeSpace(v2, i2, p2.z(), free_space_ratio))
    return false;
  const ScalePyramid& pyr = *f1.pyramid;
  if (!reprojectionOk(cam, pyr, p1, f1.kps[i1], f1.right_u[i1], f1.right_u[i1] >= 0) ||
      !reprojectionOk(cam, pyr, p2, f2.kps[i2], f2.right_u[i2], f2.right_u[i2] >= 0))
    return false;
  return scaleConsistent(v1, v2, i1, i2, X);
}

}  // namespace slam
}  // namespace yolo_slam
