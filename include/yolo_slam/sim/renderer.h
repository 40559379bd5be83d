#pragma once
// Rasteriser of textured planar quads with a z-buffer. Each quad is drawn over the bounding box
// of its projection by intersecting every pixel ray with the quad's plane, so depth is exact
// geometry (no interpolation error) and textures are perspective-correct; a per-pixel mip level
// keeps far and grazing surfaces free of aliasing. People are quads whose texture carries alpha
// (a cut-out) and a depth relief.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/sim/textures.h"

#include <opencv2/core.hpp>

#include <vector>

namespace yolo_slam {
namespace sim {

// A cut-out: colour with alpha (CV_8UC4, alpha >= 128 = inside) and a relief (CV_32F metres,
// how much nearer to the camera than the quad's plane each pixel is).
struct Sprite {
  cv::Mat bgra;
  cv::Mat relief;
};

// Fine pattern fixed to a quad's surface (clothing on a person): a crop of one of the renderer's
// textures, laid over the quad in its own (a, b) coordinates, scales the luminance of the quad's
// colour, so the pattern moves rigidly with the quad whatever its sprite shows.
struct SurfaceDetail {
  int texture = -1;     // index into the renderer's textures; -1 = no detail
  cv::Rect2f tex_rect;  // texel rectangle of level 0 spanning the quad (rows against edge_v)
  float gain = 0.f;     // colour *= 1 + gain * (min(luminance / mean, 2) - 1), never below 0
  float mean = 128.f;   // luminance that leaves the colour unchanged (the crop's mean)
};

struct Quad {
  // Corners origin + a * edge_u + b * edge_v for a, b in [0, 1] (world frame, metres). Texture
  // columns run along edge_u, texture rows run against edge_v (edge_v points "up").
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d edge_u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d edge_v = Eigen::Vector3d::UnitZ();
  int texture = -1;               // index into the renderer's textures (ignored for sprites)
  cv::Rect2f tex_rect;            // texel rectangle of level 0; a negative width mirrors
  float brightness = 1.f;         // flat shading factor
  float saturation = 1.f;         // colour grading: 0 = grey version of the photograph
  cv::Vec3f tint{1.f, 1.f, 1.f};  // colour grading: BGR multipliers (walls, floor, ceiling)
  bool two_sided = true;          // false: visible only from the side edge_u x edge_v points to
  int object_id = 0;              // 0 = static scene, > 0 = dynamic object id (mask, boxes)
  const Sprite* sprite = nullptr; // cut-out texture (alpha test + relief) instead of `texture`
  SurfaceDetail detail;           // sprites only
};

struct RenderOutput {
  cv::Mat bgr;    // CV_8UC3
  cv::Mat depth;  // CV_32F exact metres along the optical axis, 0 where nothing was hit
  cv::Mat ids;    // CV_16U object id per pixel (0 = static)
};

class Renderer {
 public:
  Renderer(const CameraModel& cam, const std::vector<Texture>& textures);

  // Renders the quads seen from camera pose T_wc (camera-to-world).
  void render(const Pose& T_wc, const std::vector<Quad>& quads, RenderOutput& out) const;

  // Pixels the quads of `object_id` would cover with no occluder and an unbounded image
  // (clamped to three times the image size): the denominator of the visible fraction.
  double unoccludedArea(const Pose& T_wc, const std::vector<Quad>& quads, int object_id) const;

 private:
  CameraModel cam_;
  const std::vector<Texture>& textures_;
};

}  // namespace sim
}  // namespace yolo_slam
