#pragma once
// "Flat box" test (beyond the paper): is the keypoint set that the screener would drop in a
// detector box a real object standing in front of its surroundings, or a piece of a static
// surface that continues past the box (a photograph of a person on a wall, a desk under a
// false detection)? A real person occludes what is around it; a picture lies flush with it.
//
// Under a pinhole camera the inverse depth of a plane is affine in the pixel coordinates:
// n.X = d with X = z K^-1 (u, v, 1)^T gives 1/z = n.K^-1 (u, v, 1)^T / d = a u + b v + c,
// so the fit needs no intrinsics (any plane, tilted or not, is three numbers). Structured
// light and stereo depth noise is nearly constant in inverse depth (sigma_z ~ k z^2), so one
// tolerance in 1/m holds at every distance.
#include "yolo_slam/features/feature_frame.h"

#include <opencv2/core.hpp>

#include <cmath>
#include <vector>

namespace yolo_slam {
namespace screening {

// 1/z = a u + b v + c (1/m, u and v in pixels).
struct InverseDepthPlane {
  double a = 0, b = 0, c = 0;
  double at(double u, double v) const { return a * u + b * v + c; }
  // |1/z - plane(u, v)| in 1/m.
  double residual(const cv::Point2f& p, float depth) const {
    return std::abs(1.0 / depth - at(p.x, p.y));
  }
};

struct FlatBoxOptions {
  double ring = 0.25;          // width of the ring around the box, fraction of its width/height
  double tolerance = 0.01;     // inverse-depth residual (1/m) counted as "on the plane"
  double fraction = 0.4;       // ring keypoints (with depth) on the cluster's plane to call it flat
  int min_points = 8;          // fewer cluster keypoints with depth: never flat
  // Fewer ring keypoints with depth: never flat. A picture or desk sits in textured
  // surroundings (43-140 ring keypoints in static_xyz's false detections); a few ring points
  // (a person clipped by the image border) are too weak a witness (docs/screening.md).
  int ring_min_points = 20;
  unsigned seed = 0;           // RANSAC seed (deterministic)
};

struct FlatBoxResult {
  bool flat = false;
  int cluster_points = 0;   // would-be-dropped keypoints with depth
  int cluster_inliers = 0;  // of those, on the fitted plane
  int ring_points = 0;      // keypoints with depth in the ring
  int ring_on_plane = 0;    // of those, on the cluster's plane
  double ringFraction() const { return ring_points > 0 ? double(ring_on_plane) / ring_points : 0; }
  InverseDepthPlane plane;
};

// Robust fit (RANSAC over 3-point samples, then least squares on the inliers) of the inverse
// depth plane through the given pixels and depths (depths > 0, at least 3 points). Returns the
// number of inliers within `tolerance` (1/m); 0 when the points are degenerate (collinear).
int fitInverseDepthPlane(const std::vector<cv::Point2f>& pts, const std::vector<float>& depths,
                         double tolerance, unsigned seed, InverseDepthPlane& plane,
                         int iterations = 200);

// The test for one box. `box`: the region the screener used (already dilated); `cluster`:
// indices into frame of the keypoints it would drop (only those with depth > 0 are used).
// The ring is `box` grown by options.ring per side minus `box`. Flat when the cluster has a
// plane (at least half of it within tolerance) and at least options.fraction of the ring's
// keypoints with depth lie on that plane: the surface continues past the box. Ring keypoints
// inside any of `exclude` (the frame's other boxes) are left out: a second person walking next
// to the first stands at the same depth and is not the surroundings.
FlatBoxResult testFlatBox(const features::FeatureFrame& frame, const cv::Rect2f& box,
                          const std::vector<int>& cluster, const FlatBoxOptions& options,
                          const std::vector<cv::Rect2f>& exclude = {});

}  // namespace screening
}  // namespace yolo_slam
