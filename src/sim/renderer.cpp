#include "yolo_slam/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace yolo_slam {
namespace sim {

namespace {

constexpr double kNear = 0.05;  // metres: geometry nearer than this is clipped
// Brightest detail texel relative to its crop's mean: bright specks in a dark crop would
// otherwise turn parts of a person white.
constexpr float kMaxDetailRatio = 2.f;

// A quad transformed into the camera frame, with the plane facing the camera (h < 0).
struct Setup {
  Eigen::Vector3d o, eu, ev, n;
  double h = 0, euo = 0, evo = 0, inv_eu2 = 0, inv_ev2 = 0;
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;  // inclusive pixel bounds
};

bool setupQuad(const CameraModel& cam, const Pose& T_cw, const Quad& q, int bx0, int by0, int bx1,
               int by1, Setup& s) {
  s.o = T_cw * q.origin;
  s.eu = T_cw.linear() * q.edge_u;
  s.ev = T_cw.linear() * q.edge_v;
  s.n = s.eu.cross(s.ev).normalized();
  s.h = s.n.dot(s.o);
  if (!q.two_sided && s.h >= 0) return false;  // seen from behind
  if (s.h > 0) {
    s.n = -s.n;
    s.h = -s.h;
  }
  if (s.h > -1e-9) return false;  // edge-on
  s.euo = s.eu.dot(s.o);
  s.evo = s.ev.dot(s.o);
  s.inv_eu2 = 1.0 / s.eu.squaredNorm();
  s.inv_ev2 = 1.0 / s.ev.squaredNorm();

  // Clip the polygon against the near plane, then take the projected bounding box.
  Eigen::Vector3d c[4] = {s.o, s.o + s.eu, s.o + s.eu + s.ev, s.o + s.ev};
  double umin = 1e18, umax = -1e18, vmin = 1e18, vmax = -1e18;
  int n_in = 0;
  auto add = [&](const Eigen::Vector3d& p) {
    double u = cam.fx * p.x() / p.z() + cam.cx, v = cam.fy * p.y() / p.z() + cam.cy;
    umin = std::min(umin, u), umax = std::max(umax, u);
    vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    ++n_in;
  };
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d& a = c[i];
    const Eigen::Vector3d& b = c[(i + 1) % 4];
    if (a.z() >= kNear) add(a);
    if ((a.z() >= kNear) != (b.z() >= kNear)) add(a + (b - a) * ((kNear - a.z()) / (b.z() - a.z())));
  }
  if (n_in == 0) return false;
  s.x0 = std::max(bx0, (int)std::floor(umin));
  s.x1 = std::min(bx1, (int)std::ceil(umax));
  s.y0 = std::max(by0, (int)std::floor(vmin));
  s.y1 = std::min(by1, (int)std::ceil(vmax));
  return s.x0 <= s.x1 && s.y0 <= s.y1;
}

// Bilinear sample of an 8-bit image with C interleaved channels, clamped to the image.
template <int C>
inline void bilinear(const cv::Mat& img, float x, float y, float out[C]) {
  x = std::min(std::max(x, 0.f), img.cols - 1.001f);
  y = std::min(std::max(y, 0.f), img.rows - 1.001f);
  int ix = (int)x, iy = (int)y;
  float fx = x - ix, fy = y - iy;
  const uchar* p0 = img.ptr<uchar>(iy) + C * ix;
  const uchar* p1 = p0 + img.step[0];
  for (int k = 0; k < C; ++k)
    out[k] = (1 - fy) * ((1 - fx) * p0[k] + fx * p0[k + C]) + fy * ((1 - fx) * p1[k] + fx * p1[k + C]);
}

inline uchar sat(float v) { return (uchar)std::min(255.f, std::max(0.f, v + 0.5f)); }

// Texels of level 0 per metre of surface (worst direction), for the mip level.
double texelsPerMetre(const cv::Rect2f& tr, const Setup& s) {
  return std::max(std::abs(tr.width) * std::sqrt(s.inv_eu2), std::abs(tr.height) * std::sqrt(s.inv_ev2));
}

// Bilinear sample of the mip level matching the pixel's footprint on the texture, which grows
// with depth and with obliquity (`cosang`: cosine between the ray and the surface normal).
inline void mipSample(const Texture& tex, double tpm, double z_ifx, double cosang, float tx, float ty,
                      float col[3]) {
  const double fp = z_ifx * tpm / std::sqrt(std::max(cosang, 0.05));
  int L = 0;
  if (fp > 1.0) L = std::min((int)tex.levels.size() - 1, std::ilogb(fp));
  const float sc = 1.f / (float)(1 << L);
  bilinear<3>(tex.levels[L], tx * sc - 0.5f, ty * sc - 0.5f, col);
}

// Everything drawQuad needs besides the quad.
struct DrawContext {
  const CameraModel& cam;
  const std::vector<Texture>& textures;
  RenderOutput& out;
};

void drawQuad(const DrawContext& c, const Quad& q, const Setup& s) {
  const double ifx = 1.0 / c.cam.fx, ify = 1.0 / c.cam.fy;
  const Texture* tex = q.sprite ? nullptr : &c.textures.at(q.texture);
  const cv::Rect2f tr = q.tex_rect;
  const double tpm = texelsPerMetre(tr, s);
  const SurfaceDetail& dt = q.detail;
  const Texture* detail = q.sprite && dt.texture >= 0 && dt.gain != 0.f ? &c.textures.at(dt.texture) : nullptr;
  const double detail_tpm = detail ? texelsPerMetre(dt.tex_rect, s) : 0;
  const float gb = q.brightness * q.tint[0], gg = q.brightness * q.tint[1], gr = q.brightness * q.tint[2];
  const float sat_k = q.saturation;
  const bool grade = sat_k != 1.f;
  for (int v = s.y0; v <= s.y1; ++v) {
    const double yt = (v - c.cam.cy) * ify;
    float* zrow = c.out.depth.ptr<float>(v);
    uchar* crow = c.out.bgr.ptr<uchar>(v);
    uint16_t* irow = c.out.ids.ptr<uint16_t>(v);
    for (int u = s.x0; u <= s.x1; ++u) {
      const double xt = (u - c.cam.cx) * ifx;
      const double D = s.n.x() * xt + s.n.y() * yt + s.n.z();
      if (D >= -1e-12) continue;
      const double invD = 1.0 / D;
      float z = (float)(s.h * invD);
      if (z >= zrow[u] || z < kNear) continue;
      const double a = (s.h * (s.eu.x() * xt + s.eu.y() * yt + s.eu.z()) * invD - s.euo) * s.inv_eu2;
      if (a < 0 || a > 1) continue;
      const double b = (s.h * (s.ev.x() * xt + s.ev.y() * yt + s.ev.z()) * invD - s.evo) * s.inv_ev2;
      if (b < 0 || b > 1) continue;
      const float tx = (float)(tr.x + a * tr.width), ty = (float)(tr.y + (1 - b) * tr.height);
      const double cosang = -D / std::sqrt(xt * xt + yt * yt + 1.0);
      float col[4];
      if (q.sprite) {
        const cv::Mat& img = q.sprite->bgra;
        bilinear<4>(img, tx - 0.5f, ty - 0.5f, col);
        if (col[3] < 128.f) continue;
        int rx = std::min(std::max((int)tx, 0), img.cols - 1);
        int ry = std::min(std::max((int)ty, 0), img.rows - 1);
        const float z_plane = z;
        z -= q.sprite->relief.at<float>(ry, rx);
        if (z >= zrow[u] || z < kNear) continue;
        if (detail) {
          float d[3];
          mipSample(*detail, detail_tpm, z_plane * ifx, cosang, (float)(dt.tex_rect.x + a * dt.tex_rect.width),
                    (float)(dt.tex_rect.y + (1 - b) * dt.tex_rect.height), d);
          const float lum = 0.114f * d[0] + 0.587f * d[1] + 0.299f * d[2];
          const float k = std::max(0.f, 1.f + dt.gain * (std::min(lum / dt.mean, kMaxDetailRatio) - 1.f));
          for (int i = 0; i < 3; ++i) col[i] *= k;
        }
      } else {
        mipSample(*tex, tpm, z * ifx, cosang, tx, ty, col);
      }
      if (grade) {
        const float grey = 0.114f * col[0] + 0.587f * col[1] + 0.299f * col[2];
        for (int k = 0; k < 3; ++k) col[k] = grey + sat_k * (col[k] - grey);
      }
      zrow[u] = z;
      crow[3 * u] = sat(col[0] * gb);
      crow[3 * u + 1] = sat(col[1] * gg);
      crow[3 * u + 2] = sat(col[2] * gr);
      irow[u] = (uint16_t)q.object_id;
    }
  }
}

}  // namespace

Renderer::Renderer(const CameraModel& cam, const std::vector<Texture>& textures)
    : cam_(cam), textures_(textures) {}

void Renderer::render(const Pose& T_wc, const std::vector<Quad>& quads, RenderOutput& out) const {
  const int W = cam_.width, H = cam_.height;
  out.bgr.create(H, W, CV_8UC3);
  out.bgr.setTo(cv::Scalar::all(0));
  out.depth.create(H, W, CV_32F);
  out.depth.setTo(std::numeric_limits<float>::infinity());
  out.ids.create(H, W, CV_16U);
  out.ids.setTo(0);
  const Pose T_cw = T_wc.inverse();

  // Near quads first so that hidden pixels of far ones fail the depth test before sampling.
  std::vector<std::pair<double, size_t>> order;
  order.reserve(quads.size());
  for (size_t i = 0; i < quads.size(); ++i) {
    const Quad& q = quads[i];
    Eigen::Vector3d c = T_cw * (q.origin + 0.5 * (q.edge_u + q.edge_v));
    order.emplace_back(c.norm(), i);
  }
  std::sort(order.begin(), order.end());

  const DrawContext ctx{cam_, textures_, out};
  for (const auto& oi : order) {
    Setup s;
    if (setupQuad(cam_, T_cw, quads[oi.second], 0, 0, W - 1, H - 1, s)) drawQuad(ctx, quads[oi.second], s);
  }
  // Pixels that saw nothing (outside the room) have no depth.
  cv::Mat none = out.depth == std::numeric_limits<float>::infinity();
  out.depth.setTo(0, none);
}

double Renderer::unoccludedArea(const Pose& T_wc, const std::vector<Quad>& quads, int object_id) const {
  const int W = cam_.width, H = cam_.height;
  const Pose T_cw = T_wc.inverse();
  const double ifx = 1.0 / cam_.fx, ify = 1.0 / cam_.fy;
  double area = 0;
  for (const Quad& q : quads) {
    if (q.object_id != object_id) continue;
    Setup s;
    if (!setupQuad(cam_, T_cw, q, -W, -H, 2 * W - 1, 2 * H - 1, s)) continue;
    const cv::Rect2f tr = q.tex_rect;
    for (int v = s.y0; v <= s.y1; ++v) {
      const double yt = (v - cam_.cy) * ify;
      for (int u = s.x0; u <= s.x1; ++u) {
        const double xt = (u - cam_.cx) * ifx;
        const double D = s.n.x() * xt + s.n.y() * yt + s.n.z();
        if (D >= -1e-12) continue;
        const double invD = 1.0 / D;
        if (s.h * invD < kNear) continue;
        const double a = (s.h * (s.eu.x() * xt + s.eu.y() * yt + s.eu.z()) * invD - s.euo) * s.inv_eu2;
        if (a < 0 || a > 1) continue;
        const double b = (s.h * (s.ev.x() * xt + s.ev.y() * yt + s.ev.z()) * invD - s.evo) * s.inv_ev2;
        if (b < 0 || b > 1) continue;
        if (q.sprite) {
          const cv::Mat& img = q.sprite->bgra;
          int rx = std::min(std::max((int)(tr.x + a * tr.width), 0), img.cols - 1);
          int ry = std::min(std::max((int)(tr.y + (1 - b) * tr.height), 0), img.rows - 1);
          if (img.ptr<uchar>(ry)[4 * rx + 3] < 128) continue;
        }
        area += 1;
      }
    }
  }
  return area;
}

}  // namespace sim
}  // namespace yolo_slam
