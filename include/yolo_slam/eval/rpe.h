#pragma once
// Relative pose error as TUM's evaluate_rpe.py with --fixed_delta. Reproduced details:
// - poses with equal stamps: the last one is kept (the script's dict);
// - for each estimate pose i (sorted by stamp), j = the index whose "index value" is closest
//   to index(i) + delta (find_closest_index, a binary search keeping the first strictly closer
//   element), where the index value is the stamp (unit s) or the position (unit f); pairs with
//   j equal to the LAST estimate index are skipped, as in the script;
// - each estimate stamp is matched to the NEAREST ground-truth stamp (+offset); a pair is
//   skipped when either match is further than max_time_diff (default: 2 x the median
//   ground-truth interval, as the script);
// - error = ominus(ominus(est_j, est_i), ominus(gt_j, gt_i)) with ominus(a, b) = inv(a) b,
//   i.e. E = (inv(est_i) est_j) inv(inv(gt_i) gt_j). Its rotation angle equals that of the
//   paper's inv(inv(gt_i) gt_j) (inv(est_i) est_j) (conjugate matrices); its translation norm
//   is the script's, which published tables were computed with.
// Not reproduced: the script's random down-sampling to 10000 pairs (all pairs are used) and
// its silent skipping of NaN lines (readTrajectory rejects them).
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/eval/stats.h"

#include <string>
#include <vector>

namespace yolo_slam {
namespace eval {

enum class DeltaUnit { Seconds, Frames };
DeltaUnit parseDeltaUnit(const std::string& s);  // "s" | "f"; throws yolo_slam::Error otherwise
std::string toString(DeltaUnit u);

struct RpeOptions {
  double delta = 1.0;
  DeltaUnit unit = DeltaUnit::Seconds;
  // Largest |gt stamp - (est stamp + offset)| accepted; <= 0 means 2 x the median interval of
  // the ground truth (evaluate_rpe.py's rule).
  double max_time_diff = 0.0;
  double offset = 0.0;  // added to estimate stamps
};

struct RpePair {
  double est_stamp0, est_stamp1, gt_stamp0, gt_stamp1;
  double trans;    // m
  double rot_deg;  // degrees
};

struct RpeResult {
  ErrorStats trans;      // metres per delta
  ErrorStats rot_deg;    // degrees per delta
  double max_time_diff = 0;  // the value actually used
  std::vector<RpePair> pairs;
};

// Throws yolo_slam::Error if a trajectory has < 2 poses, delta is not > 0, or fewer than 2
// pairs can be formed (no overlapping timestamps).
RpeResult computeRpe(const Trajectory& gt, const Trajectory& est, const RpeOptions& opt = {});

// evaluate_rpe.py's find_closest_index on a sorted list (exposed for tests).
size_t findClosestIndex(const std::vector<double>& sorted, double t);

}  // namespace eval
}  // namespace yolo_slam
