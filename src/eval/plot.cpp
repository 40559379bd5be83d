#include "yolo_slam/eval/plot.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/io/atomic_file.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace yolo_slam {
namespace eval {
namespace {

const cv::Scalar kWhite(255, 255, 255), kBlack(0, 0, 0), kGrid(225, 225, 225),
    kAxisText(70, 70, 70), kGt(30, 30, 30), kEst(200, 110, 20), kDiff(150, 150, 255),
    kErr(30, 30, 210);
const int kFont = cv::FONT_HERSHEY_SIMPLEX;

// Pixel coordinates are clamped this far outside the figure: cv::line clips what it is given,
// and a point this far out already draws as an edge-to-edge line.
constexpr double kMaxPixelReach = 1e5;

int clampedPixel(double v) { return static_cast<int>(std::lround(std::clamp(v, -kMaxPixelReach, kMaxPixelReach))); }

// A "nice" step (1, 2 or 5 x 10^k) giving about `ticks` intervals over `range`.
double niceStep(double range, int ticks) {
  double raw = range / ticks;
  double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * mag >= raw) return m * mag;
  }
  return 10 * mag;
}

std::string fmt(double v, double step) {
  int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, std::abs(v) < step * 1e-6 ? 0.0 : v);
  return buf;
}

void text(cv::Mat& img, const std::string& s, cv::Point p, double scale, const cv::Scalar& c,
          int thickness = 1) {
  cv::putText(img, s, p, kFont, scale, c, thickness, cv::LINE_AA);
}

// Text centred horizontally on x (and vertically on y when `vcenter`).
void textCentered(cv::Mat& img, const std::string& s, cv::Point p, double scale,
                  const cv::Scalar& c, bool vcenter = false) {
  int base = 0;
  cv::Size sz = cv::getTextSize(s, kFont, scale, 1, &base);
  text(img, s, {p.x - sz.width / 2, vcenter ? p.y + sz.height / 2 : p.y}, scale, c);
}

void textRight(cv::Mat& img, const std::string& s, cv::Point p, double scale, const cv::Scalar& c) {
  int base = 0;
  cv::Size sz = cv::getTextSize(s, kFont, scale, 1, &base);
  text(img, s, {p.x - sz.width, p.y + sz.height / 2}, scale, c);
}

void polyline(cv::Mat& img, const std::vector<cv::Point>& pts, const cv::Scalar& c, int thickness) {
  if (pts.size() >= 2) cv::polylines(img, pts, false, c, thickness, cv::LINE_AA);
}

// The grids step through the extents: only finite, bounded values give a finite number of steps.
void checkPlottable(const Trajectory& gt, const Trajectory& est, const AteResult& ate) {
  bool ok = std::isfinite(ate.stats.max) && ate.alignment.matrix().allFinite();
  for (const auto* traj : {&gt, &est})
    for (const StampedPose& p : *traj)
      ok = ok && std::isfinite(p.stamp) && p.T_wc.translation().allFinite() &&
           p.T_wc.translation().cwiseAbs().maxCoeff() <= kMaxCoordinateM;
  if (!ok)
    throw Error("ATE plot: a position or the error is not finite or beyond 1e9 m; the trajectories cannot be drawn");
}

// The top view: the two axes with the largest extent of both trajectories, fitted into a panel.
struct TopView {
  cv::Rect view;
  int ax = 0, ay = 1;               // world axes drawn as the panel's x and y
  double scale = 1;                 // pixels per metre
  double cxm = 0, cym = 0;          // world coordinates at the panel's centre
  double step = 1;                  // grid step, metres

  cv::Point toPx(const Eigen::Vector3d& p) const {
    return cv::Point(clampedPixel(view.x + view.width / 2 + (p[ax] - cxm) * scale),
                     clampedPixel(view.y + view.height / 2 - (p[ay] - cym) * scale));
  }
};

// Fraction of the panel the trajectories' extent fills.
constexpr double kTopViewFill = 0.86;

TopView fitTopView(const cv::Rect& view, const std::vector<Eigen::Vector3d>& gt_pts,
                   const std::vector<Eigen::Vector3d>& est_pts) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
  for (const auto* set : {&gt_pts, &est_pts}) {
    for (const auto& p : *set) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  const Eigen::Vector3d ext = hi - lo;
  // The two axes with the largest extent, kept in x, y, z order (x-y for a usual top view).
  int drop = 0;
  for (int k = 1; k < 3; ++k) {
    if (ext[k] < ext[drop]) drop = k;
  }
  TopView tv;
  tv.view = view;
  tv.ax = drop == 0 ? 1 : 0;
  tv.ay = drop == 2 ? 1 : 2;
  const double ex = std::max(ext[tv.ax], 1e-3), ey = std::max(ext[tv.ay], 1e-3);
  tv.scale = kTopViewFill * std::min(view.width / ex, view.height / ey);
  tv.cxm = 0.5 * (lo[tv.ax] + hi[tv.ax]);
  tv.cym = 0.5 * (lo[tv.ay] + hi[tv.ay]);
  tv.step = niceStep(std::max(view.width / tv.scale, view.height / tv.scale), 8);
  return tv;
}

// Metre grid, tick labels and axis names.
void drawTopGrid(cv::Mat& img, const TopView& tv) {
  const cv::Rect& view = tv.view;
  const double span_x = view.width / tv.scale, span_y = view.height / tv.scale;
  const double x_min = tv.cxm - span_x / 2, y_min = tv.cym - span_y / 2;
  for (double g = std::ceil(x_min / tv.step) * tv.step; g <= x_min + span_x; g += tv.step) {
    int u = static_cast<int>(std::lround(view.x + (g - x_min) * tv.scale));
    cv::line(img, {u, view.y}, {u, view.y + view.height}, kGrid, 1);
    textCentered(img, fmt(g, tv.step), {u, view.y + view.height + 20}, 0.45, kAxisText);
  }
  for (double g = std::ceil(y_min / tv.step) * tv.step; g <= y_min + span_y; g += tv.step) {
    int v = static_cast<int>(std::lround(view.y + view.height - (g - y_min) * tv.scale));
    cv::line(img, {view.x, v}, {view.x + view.width, v}, kGrid, 1);
    textRight(img, fmt(g, tv.step), {view.x - 8, v}, 0.45, kAxisText);
  }
  cv::rectangle(img, view, kAxisText, 1);
  const char* names[3] = {"x", "y", "z"};
  textCentered(img, std::string(names[tv.ax]) + " [m]",
               {view.x + view.width / 2, view.y + view.height + 44}, 0.55, kBlack);
  text(img, std::string(names[tv.ay]) + " [m]", {12, view.y + 14}, 0.55, kBlack);
}

// The error segments and both trajectories, clipped to the panel.
void drawTrajectories(cv::Mat& img, const TopView& tv, const AteResult& ate,
                      const std::vector<Eigen::Vector3d>& gt_pts,
                      const std::vector<Eigen::Vector3d>& est_pts) {
  cv::Mat canvas = img.clone();
  for (size_t k = 0; k < ate.gt_positions.size(); ++k) {
    cv::line(canvas, tv.toPx(ate.gt_positions[k]), tv.toPx(ate.est_aligned[k]), kDiff, 1, cv::LINE_AA);
  }
  std::vector<cv::Point> g, e;
  for (const auto& p : gt_pts) g.push_back(tv.toPx(p));
  for (const auto& p : est_pts) e.push_back(tv.toPx(p));
  polyline(canvas, g, kGt, 3);  // under the estimate, wider so it stays visible
  polyline(canvas, e, kEst, 1);
  canvas(tv.view).copyTo(img(tv.view));
  cv::rectangle(img, tv.view, kAxisText, 1);
}

// Legend (top left) and scale bar (bottom right) of the top view.
void drawLegend(cv::Mat& img, const TopView& tv) {
  const cv::Rect& view = tv.view;
  const cv::Rect box(view.x + 12, view.y + 12, 250, 88);
  cv::rectangle(img, box, kWhite, cv::FILLED);
  cv::rectangle(img, box, kAxisText, 1);
  const std::pair<const char*, cv::Scalar> items[3] = {
      {"ground truth", kGt}, {"estimate (aligned)", kEst}, {"error (matched pairs)", kDiff}};
  for (int k = 0; k < 3; ++k) {
    int y = box.y + 20 + 25 * k;
    cv::line(img, {box.x + 10, y}, {box.x + 45, y}, items[k].second, k == 0 ? 3 : 2, cv::LINE_AA);
    text(img, items[k].first, {box.x + 55, y + 5}, 0.5, kBlack);
  }
  const int bar = static_cast<int>(std::lround(tv.step * tv.scale));
  const int bx1 = view.x + view.width - 20, bx0 = bx1 - bar, by = view.y + view.height - 22;
  cv::rectangle(img, cv::Rect(bx0 - 10, by - 28, bar + 20, 40), kWhite, cv::FILLED);
  cv::line(img, {bx0, by}, {bx1, by}, kBlack, 3);
  cv::line(img, {bx0, by - 6}, {bx0, by + 6}, kBlack, 2);
  cv::line(img, {bx1, by - 6}, {bx1, by + 6}, kBlack, 2);
  textCentered(img, fmt(tv.step, tv.step) + " m", {(bx0 + bx1) / 2, by - 10}, 0.5, kBlack);
}

// The error-over-time panel's axes: time from the first matched pose, error up to its maximum.
struct ErrorAxes {
  cv::Rect panel;
  double t0 = 0, tr = 1, emax = 1;

  cv::Point toPx(double t, double e) const {
    return cv::Point(clampedPixel(panel.x + (t - t0) / tr * panel.width),
                     clampedPixel(panel.y + panel.height - e / emax * panel.height));
  }
};

// Headroom above the largest error.
constexpr double kErrorHeadroom = 1.1;

// The dashed RMSE line with its labelled box in the panel's top right.
void drawRmseLine(cv::Mat& img, const ErrorAxes& axes, double rmse) {
  const cv::Rect& panel = axes.panel;
  const int y = axes.toPx(axes.t0, rmse).y;
  for (int x = panel.x; x < panel.x + panel.width; x += 16) {
    cv::line(img, {x, y}, {std::min(x + 9, panel.x + panel.width), y}, kBlack, 1, cv::LINE_AA);
  }
  char buf[64];
  std::snprintf(buf, sizeof(buf), "- - rmse %.4f m", rmse);
  int base = 0;
  cv::Size sz = cv::getTextSize(buf, kFont, 0.5, 1, &base);
  const cv::Point at(panel.x + panel.width - sz.width - 10, panel.y + 8);
  cv::rectangle(img, cv::Rect(at.x - 6, at.y - 2, sz.width + 12, sz.height + 12), kWhite, cv::FILLED);
  cv::rectangle(img, cv::Rect(at.x - 6, at.y - 2, sz.width + 12, sz.height + 12), kAxisText, 1);
  text(img, buf, {at.x, at.y + sz.height + 3}, 0.5, kBlack);
}

void drawErrorPanel(cv::Mat& img, const cv::Rect& panel, const AteResult& ate) {
  ErrorAxes axes;
  axes.panel = panel;
  axes.t0 = ate.gt_stamps.empty() ? 0.0 : ate.gt_stamps.front();
  const double t1 = ate.gt_stamps.empty() ? 1.0 : ate.gt_stamps.back();
  axes.tr = std::max(t1 - axes.t0, 1e-3);
  axes.emax = std::max(ate.stats.max * kErrorHeadroom, 1e-4);
  const double tstep = niceStep(axes.tr, 10), estep = niceStep(axes.emax, 4);
  for (double g = 0; g <= axes.tr + 1e-9; g += tstep) {
    cv::Point p = axes.toPx(axes.t0 + g, 0);
    cv::line(img, {p.x, panel.y}, {p.x, panel.y + panel.height}, kGrid, 1);
    textCentered(img, fmt(g, tstep), {p.x, panel.y + panel.height + 20}, 0.45, kAxisText);
  }
  for (double g = 0; g <= axes.emax + 1e-12; g += estep) {
    cv::Point p = axes.toPx(axes.t0, g);
    cv::line(img, {panel.x, p.y}, {panel.x + panel.width, p.y}, kGrid, 1);
    textRight(img, fmt(g, estep), {panel.x - 8, p.y}, 0.45, kAxisText);
  }
  cv::rectangle(img, panel, kAxisText, 1);
  std::vector<cv::Point> ep;
  for (size_t k = 0; k < ate.errors.size(); ++k) ep.push_back(axes.toPx(ate.gt_stamps[k], ate.errors[k]));
  polyline(img, ep, kErr, 2);
  drawRmseLine(img, axes, ate.stats.rmse);
  text(img, "translational error [m]", {panel.x, panel.y - 10}, 0.55, kBlack);
  textCentered(img, "time [s] (from first matched pose)",
               {panel.x + panel.width / 2, panel.y + panel.height + 44}, 0.55, kBlack);
}

}  // namespace

cv::Mat renderAtePlot(const Trajectory& gt_in, const Trajectory& est_in, const AteResult& ate,
                      const std::string& title) {
  checkPlottable(gt_in, est_in, ate);
  const int W = 1000, H = 1120;
  cv::Mat img(H, W, CV_8UC3, kWhite);
  std::vector<Eigen::Vector3d> gt_pts, est_pts;
  for (const auto& p : uniqueByStamp(gt_in)) gt_pts.push_back(p.T_wc.translation());
  for (const auto& p : uniqueByStamp(est_in)) est_pts.push_back(ate.alignment * p.T_wc.translation());

  text(img, title, {20, 34}, 0.75, kBlack, 2);
  const TopView tv = fitTopView(cv::Rect(90, 60, 880, 720), gt_pts, est_pts);
  drawTopGrid(img, tv);
  drawTrajectories(img, tv, ate, gt_pts, est_pts);
  drawLegend(img, tv);
  drawErrorPanel(img, cv::Rect(90, 870, 880, 190), ate);
  return img;
}

void writeAtePlot(const std::string& path, const Trajectory& gt, const Trajectory& est,
                  const AteResult& ate, const std::string& title) {
  if (path.size() < 5 || path.compare(path.size() - 4, 4, ".png") != 0) {
    throw Error(path + ": the plot is written as PNG; give a file name ending in .png");
  }
  std::vector<uchar> buf;
  if (!cv::imencode(".png", renderAtePlot(gt, est, ate, title), buf)) {
    throw Error(path + ": PNG encoding failed");
  }
  io::writeFileAtomic(path, std::string(buf.begin(), buf.end()));
}

}  // namespace eval
}  // namespace yolo_slam
