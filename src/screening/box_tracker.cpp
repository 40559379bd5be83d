#include "yolo_slam/screening/box_tracker.h"

#include "yolo_slam/common/option_checks.h"
#include "yolo_slam/features/match_near.h"
#include "yolo_slam/screening/screener.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>

namespace yolo_slam {
namespace screening {

namespace {
constexpr float kNearPersonHeight = 0.9f;  // share of the image's height (isNearPersonBox)
}  // namespace

bool isNearPersonBox(const cv::Rect2f& box, int width, int height, double near_fraction) {
  const double image_area = static_cast<double>(width) * height;
  return image_area > 0 && near_fraction < 1 && box.area() >= near_fraction * image_area &&
         box.height >= kNearPersonHeight * height;
}

double iou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const float inter = (a & b).area();
  const float uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

namespace {

const OptionTable<BoxTrackerOptions>& trackerFields() {
  using O = BoxTrackerOptions;
  static const OptionTable<O> table = {
      {"Screening.trackBoxes", &O::enabled},
      {"Screening.trackMaxAge", &O::max_age, Range::atLeast(1)},
      {"Screening.trackRadius", &O::radius_px, Range::positive()},
      {"Screening.trackMaxHamming", &O::max_hamming, Range::closed(0, 256)},
      {"Screening.trackMinMatches", &O::min_matches, Range::atLeast(1)},
      {"Screening.trackMinScore", &O::min_score, Range::closed(0, 1)},
      {"Screening.trackShiftStale", &O::shift_stale},
      {"Screening.trackNearFraction", &O::near_fraction, Range::fraction()},
      {"Screening.trackNearMaxAge", &O::near_max_age, Range::atLeast(1)},
  };
  return table;
}

}  // namespace

BoxTrackerOptions BoxTrackerOptions::load(const Config& cfg) {
  BoxTrackerOptions o;
  readOptions(cfg, o, trackerFields());
  return o;
}

void BoxTrackerOptions::validate(const std::string& where) const {
  checkOptions(*this, where, trackerFields());
  // Set in code only, no key.
  checkOption(where, "BoxTrackerOptions::iou_associate", iou_associate, Range::fraction());
  checkOption(where, "BoxTrackerOptions::covered_fraction", covered_fraction, Range::fraction());
}

BoxTracker::BoxTracker(const BoxTrackerOptions& options) : opt_(options) { opt_.validate(); }

bool BoxTracker::displacement(const Track& t, const features::FeatureFrame& frame,
                              const features::KeypointIndex& index, cv::Point2f& d) const {
  if (t.pts.empty()) return false;
  std::vector<float> dx, dy;
  dx.reserve(t.pts.size());
  dy.reserve(t.pts.size());
  for (size_t k = 0; k < t.pts.size(); ++k) {
    const cv::Point2f p = t.pts[k];
    const int best_i =
        index.bestMatchNear(p, t.desc.ptr<uint8_t>(static_cast<int>(k)), opt_.radius_px, opt_.max_hamming);
    if (best_i < 0) continue;
    dx.push_back(frame.keypoints[best_i].pt.x - p.x);
    dy.push_back(frame.keypoints[best_i].pt.y - p.y);
  }
  if (static_cast<int>(dx.size()) < opt_.min_matches) return false;
  // Median per axis: robust to the wrong matches on repeated texture and to keypoints of the
  // background that were screened dynamic by mistake.
  auto median = [](std::vector<float>& v) {
    const size_t m = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + m, v.end());
    return v[m];
  };
  d = cv::Point2f(median(dx), median(dy));
  return true;
}

namespace {

// Two stamps closer than this are the same frame.
constexpr double kSameStampS = 1e-4;

}  // namespace

std::vector<int> BoxTracker::associate(const detection::Boxes& detections) const {
  // Greedy one-to-one association by decreasing IoU with the track's last box (ties: lower
  // track id, then lower detection index), so the result does not depend on container order
  // beyond ids.
  std::vector<std::tuple<double, size_t, size_t>> pairs;
  for (size_t t = 0; t < tracks_.size(); ++t)
    for (size_t j = 0; j < detections.size(); ++j) {
      const double v = iou(tracks_[t].box.rect, detections[j].rect);
      if (v >= opt_.iou_associate) pairs.emplace_back(v, t, j);
    }
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
    if (std::get<0>(a) != std::get<0>(b)) return std::get<0>(a) > std::get<0>(b);
    if (std::get<1>(a) != std::get<1>(b)) return std::get<1>(a) < std::get<1>(b);
    return std::get<2>(a) < std::get<2>(b);
  });
  std::vector<int> track_det(tracks_.size(), -1), det_track(detections.size(), -1);
  for (const auto& p : pairs) {
    const size_t t = std::get<1>(p), j = std::get<2>(p);
    if (track_det[t] >= 0 || det_track[j] >= 0) continue;
    track_det[t] = static_cast<int>(j);
    det_track[j] = static_cast<int>(t);
  }
  return track_det;
}

std::optional<cv::Point2f> BoxTracker::travelAt(const Track& t, double stamp) {
  for (size_t k = 0; k < t.seen.size(); ++k) {
    if (std::abs(t.seen[k].stamp - stamp) <= kSameStampS) return t.seen[k].travel;
    // Between two frames the tracker saw (the stream dropped the detected one): interpolated.
    if (k > 0 && t.seen[k - 1].stamp < stamp && stamp < t.seen[k].stamp) {
      const float a = static_cast<float>((stamp - t.seen[k - 1].stamp) / (t.seen[k].stamp - t.seen[k - 1].stamp));
      return t.seen[k - 1].travel + a * (t.seen[k].travel - t.seen[k - 1].travel);
    }
  }
  return std::nullopt;
}

detection::Box BoxTracker::placeDetection(const Track& t, const features::FeatureFrame& frame,
                                          const detection::Box& det) const {
  if (!opt_.shift_stale || det.age_s <= 0 || !t.moved_now) return det;
  const std::optional<cv::Point2f> then = travelAt(t, frame.stamp - det.age_s);
  if (!then) return det;
  const cv::Point2f shift = t.travel + *t.moved_now - *then;
  detection::Box moved = det;
  const cv::Rect2f image(0.f, 0.f, static_cast<float>(frame.width), static_cast<float>(frame.height));
  cv::Rect2f r(det.rect.x + shift.x, det.rect.y + shift.y, det.rect.width, det.rect.height);
  if (frame.width > 0 && frame.height > 0) r &= image;
  if (r.area() <= 0) return det;
  moved.rect = r;
  return moved;
}

bool BoxTracker::carry(Track& tr, const features::FeatureFrame& frame, const detection::Boxes& placed,
                       bool detector_ran) const {
  // A weak track is dropped when the detector looked and did not find it again; a frame the
  // detector never saw (asynchronous detection) carries every track.
  const cv::Rect2f image(0.f, 0.f, static_cast<float>(frame.width), static_cast<float>(frame.height));
  tr.near = tr.near || (isNearPersonBox(tr.box.rect, frame.width, frame.height, opt_.near_fraction) &&
                         tr.best_score >= opt_.min_score);
  const bool near = tr.near;
  tr.unmatched = tr.moved_now ? 0 : tr.unmatched + 1;
  const int max_age = near ? std::max(opt_.max_age, opt_.near_max_age) : opt_.max_age;
  if (++tr.age > max_age || tr.unmatched > opt_.max_age) return false;
  if (detector_ran && !near && tr.box.score < opt_.min_score) return false;
  if (!tr.moved_now && !near) return false;
  const cv::Point2f d = tr.moved_now.value_or(cv::Point2f(0.f, 0.f));
  cv::Rect2f moved(tr.box.rect.x + d.x, tr.box.rect.y + d.y, tr.box.rect.width, tr.box.rect.height);
  const cv::Rect2f visible = frame.width > 0 && frame.height > 0 ? (moved & image) : moved;
  // Mostly outside the image: the person walked out of view.
  if (!(visible.area() >= 0.2f * moved.area()) || visible.area() <= 0) return false;
  // A detection already screens this person (its box changed too much for the IoU test):
  // no duplicate; the detection's own track carries on.
  for (const auto& p : placed)
    if ((visible & p.rect).area() >= opt_.covered_fraction * visible.area()) return false;
  tr.box.rect = visible;
  tr.box.tracked = true;
  return true;
}

detection::Boxes BoxTracker::predict(const features::FeatureFrame& frame,
                                     const detection::Boxes& detections, bool detector_ran) {
  const std::vector<int> track_det = associate(detections);
  for (const auto& b : detections) stream_has_stale_ = stream_has_stale_ || b.age_s > 0;
  // How far each track's keypoints moved since the last frame: carries undetected tracks, and
  // (shift_stale, on a stream with detections of earlier images) measures the person's travel
  // that such a detection missed.
  std::optional<features::KeypointIndex> index;  // built for the first track that needs it
  for (size_t t = 0; t < tracks_.size(); ++t) {
    Track& tr = tracks_[t];
    cv::Point2f d;
    const bool needed = track_det[t] < 0 || (opt_.shift_stale && stream_has_stale_);
    if (needed && !index) index.emplace(frame, opt_.radius_px);
    tr.moved_now = needed && displacement(tr, frame, *index, d) ? std::optional<cv::Point2f>(d) : std::nullopt;
  }
  detection::Boxes out = detections;
  for (size_t t = 0; t < tracks_.size(); ++t)
    if (track_det[t] >= 0) out[track_det[t]] = placeDetection(tracks_[t], frame, detections[track_det[t]]);
  for (auto& b : out) b.tracked = false;
  const size_t nd = detections.size();
  std::vector<bool> det_used(nd, false);

  const detection::Boxes placed(out.begin(), out.end());  // the detections where screened
  std::vector<Track> kept;
  kept.reserve(tracks_.size() + nd);
  for (size_t t = 0; t < tracks_.size(); ++t) {
    Track& tr = tracks_[t];
    if (track_det[t] >= 0) {
      det_used[track_det[t]] = true;
      tr.box = out[track_det[t]];
      tr.best_score = std::max(tr.best_score, tr.box.score);
      tr.near = false;  // judged again from the detection's box when it is next carried
      tr.age = 0;
      tr.unmatched = 0;
      kept.push_back(std::move(tr));
    } else if (carry(tr, frame, placed, detector_ran)) {
      out.push_back(tr.box);
      kept.push_back(std::move(tr));
    }
  }
  for (size_t j = 0; j < nd; ++j) {
    if (det_used[j]) continue;
    Track tr;
    tr.id = next_id_++;
    tr.box = out[j];
    tr.best_score = tr.box.score;
    kept.push_back(std::move(tr));
  }
  std::sort(kept.begin(), kept.end(), [](const Track& a, const Track& b) { return a.id < b.id; });
  for (Track& tr : kept) {
    // A frame without a measured motion breaks the travel: no earlier image is shifted past it.
    if (!tr.moved_now) tr.seen.clear();
    tr.travel += tr.moved_now.value_or(cv::Point2f(0.f, 0.f));
    tr.seen.push_back({frame.stamp, tr.travel});
    if (tr.seen.size() > kSeenFrames) tr.seen.pop_front();
  }
  tracks_ = std::move(kept);
  return out;
}

void BoxTracker::observe(const features::FeatureFrame& frame) {
  const bool have_desc = frame.descriptors.rows == static_cast<int>(frame.keypoints.size()) &&
                         frame.descriptors.cols == 32 && frame.descriptors.type() == CV_8U;
  for (Track& tr : tracks_) {
    tr.pts.clear();
    tr.desc.release();
    if (!have_desc) continue;
    const cv::Rect2f& r = tr.box.rect;
    std::vector<int> idx;
    for (size_t i = 0; i < frame.keypoints.size(); ++i) {
      if (i >= frame.dynamic.size() || !frame.dynamic[i]) continue;
      const cv::Point2f p = frame.keypoints[i].pt;
      // Only the person's keypoints (screened dynamic): the background inside the box moves
      // with the camera, not with the person.
      if (p.x >= r.x && p.y >= r.y && p.x < r.x + r.width && p.y < r.y + r.height)
        idx.push_back(static_cast<int>(i));
    }
    tr.desc.create(static_cast<int>(idx.size()), 32, CV_8U);
    for (size_t k = 0; k < idx.size(); ++k) {
      tr.pts.push_back(frame.keypoints[idx[k]].pt);
      frame.descriptors.row(idx[k]).copyTo(tr.desc.row(static_cast<int>(k)));
    }
  }
}

}  // namespace screening
}  // namespace yolo_slam
