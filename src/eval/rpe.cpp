#include "yolo_slam/eval/rpe.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/eval/ate.h"

#include <cmath>
#include <vector>

namespace yolo_slam {
namespace eval {

DeltaUnit parseDeltaUnit(const std::string& s) {
  if (s == "s") return DeltaUnit::Seconds;
  if (s == "f") return DeltaUnit::Frames;
  throw Error("unknown delta unit '" + s + "'; use 's' (seconds) or 'f' (frames)");
}

std::string toString(DeltaUnit u) { return u == DeltaUnit::Seconds ? "s" : "f"; }

size_t findClosestIndex(const std::vector<double>& L, double t) {
  // Literal port of evaluate_rpe.py's binary search (same tie-breaking).
  size_t beginning = 0, end = L.size(), best = 0;
  double difference = std::abs(L[0] - t);
  while (beginning < end) {
    const size_t middle = (end + beginning) / 2;
    if (std::abs(L[middle] - t) < difference) {
      difference = std::abs(L[middle] - t);
      best = middle;
    }
    if (t == L[middle]) return middle;
    if (L[middle] > t) {
      end = middle;
    } else {
      beginning = middle + 1;
    }
  }
  return best;
}

namespace {

std::vector<double> stampsOf(const Trajectory& t) {
  std::vector<double> s;
  s.reserve(t.size());
  for (const auto& p : t) s.push_back(p.stamp);
  return s;
}

// The script's overlap check: estimate stamps that map back to themselves through the nearest
// ground-truth stamp must be at least 2 distinct ones.
void checkOverlap(const std::vector<double>& sg, const std::vector<double>& se, double offset) {
  size_t distinct = 0;
  double last = NAN;
  for (double t : se) {
    const double t_gt = sg[findClosestIndex(sg, t + offset)];
    const double t_back = se[findClosestIndex(se, t_gt - offset)];
    if (t_back != last) {  // t_back is non-decreasing in t
      ++distinct;
      last = t_back;
    }
  }
  if (distinct < 2) {
    throw Error("RPE: the timestamps of ground truth and estimate barely overlap; are these "
                "files of the same sequence?");
  }
}

// The option, or twice the ground truth's median stamp step (the script's default).
double maxTimeDiff(const RpeOptions& opt, const std::vector<double>& sg) {
  if (opt.max_time_diff > 0) return opt.max_time_diff;
  std::vector<double> dt;
  for (size_t k = 1; k < sg.size(); ++k) dt.push_back(sg[k] - sg[k - 1]);
  return 2.0 * errorStats(dt).median;
}

}  // namespace

RpeResult computeRpe(const Trajectory& gt_in, const Trajectory& est_in, const RpeOptions& opt) {
  if (!(opt.delta > 0) || !std::isfinite(opt.delta)) {
    throw Error("RPE: delta must be > 0, got " + std::to_string(opt.delta));
  }
  const Trajectory gt = uniqueByStamp(gt_in);
  const Trajectory est = uniqueByStamp(est_in);
  if (gt.size() < 2) throw Error("RPE: the ground-truth trajectory has fewer than 2 poses");
  if (est.size() < 2) throw Error("RPE: the estimated trajectory has fewer than 2 poses");
  const std::vector<double> sg = stampsOf(gt), se = stampsOf(est);
  checkOverlap(sg, se, opt.offset);

  std::vector<double> index(est.size());
  for (size_t i = 0; i < est.size(); ++i) {
    index[i] = opt.unit == DeltaUnit::Seconds ? se[i] : static_cast<double>(i);
  }
  RpeResult r;
  r.max_time_diff = maxTimeDiff(opt, sg);
  for (size_t i = 0; i < est.size(); ++i) {
    const size_t j = findClosestIndex(index, index[i] + opt.delta);
    if (j == est.size() - 1) continue;  // as the script: never pairs ending at the last pose
    const size_t g0 = findClosestIndex(sg, se[i] + opt.offset);
    const size_t g1 = findClosestIndex(sg, se[j] + opt.offset);
    if (std::abs(sg[g0] - (se[i] + opt.offset)) > r.max_time_diff ||
        std::abs(sg[g1] - (se[j] + opt.offset)) > r.max_time_diff) {
      continue;
    }
    const Pose est_rel = est[i].T_wc.inverse() * est[j].T_wc;
    const Pose gt_rel = gt[g0].T_wc.inverse() * gt[g1].T_wc;
    const Pose E = est_rel * gt_rel.inverse();
    RpePair p;
    p.est_stamp0 = se[i];
    p.est_stamp1 = se[j];
    p.gt_stamp0 = sg[g0];
    p.gt_stamp1 = sg[g1];
    p.trans = E.translation().norm();
    p.rot_deg = rotationAngle(E.linear()) * 180.0 / M_PI;
    r.pairs.push_back(p);
  }
  if (r.pairs.size() < 2) {
    throw Error("RPE: only " + std::to_string(r.pairs.size()) +
                " pose pairs could be matched to the ground truth (need >= 2); check the files, "
                "the delta, or --max-diff");
  }
  std::vector<double> te, re;
  for (const RpePair& p : r.pairs) {
    te.push_back(p.trans);
    re.push_back(p.rot_deg);
  }
  r.trans = errorStats(te);
  r.rot_deg = errorStats(re);
  return r;
}

}  // namespace eval
}  // namespace yolo_slam
