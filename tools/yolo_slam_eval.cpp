// yolo_slam_eval: absolute trajectory error and relative pose error of a TUM-format trajectory
// against ground truth, computed as the TUM RGB-D benchmark scripts (evaluate_ate.py,
// evaluate_rpe.py --fixed_delta) compute them.
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/json.h"
#include "yolo_slam/eval/ate.h"
#include "yolo_slam/eval/plot.h"
#include "yolo_slam/eval/rpe.h"
#include "yolo_slam/io/trajectory.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

using namespace yolo_slam;

namespace {

const char* kUsage =
    "usage:\n"
    "  yolo_slam_eval ate GT EST [--max-diff 0.02] [--plot out.png] [--json] [--align-with GT0 EST0]\n"
    "  yolo_slam_eval rpe GT EST [--delta 1] [--delta-unit s|f] [--max-diff SECONDS] [--json]\n"
    "\n"
    "GT and EST are TUM trajectories ('timestamp tx ty tz qx qy qz qw' per line, camera to\n"
    "world, '#' comments).\n"
    "\n"
    "ate  absolute trajectory error as TUM evaluate_ate.py: stamps associated like associate.py\n"
    "     (pairs closer than --max-diff seconds, default 0.02, greedy by smallest difference),\n"
    "     estimate aligned onto the ground truth by a rigid transform (Horn, no scale);\n"
    "     translational error statistics in metres. --plot writes a PNG with the top view and\n"
    "     the error over time. --align-with GT0 EST0: no alignment of its own; the one of EST0\n"
    "     onto GT0 is used (a run in a loaded map, evaluated in the mapping run's frame).\n"
    "rpe  relative pose error as TUM evaluate_rpe.py --fixed_delta: pose pairs --delta apart\n"
    "     (unit s = seconds, the default, or f = frames of the estimate); translational error in\n"
    "     metres per delta, rotational error in degrees per delta. Each estimate stamp is matched\n"
    "     to the nearest ground-truth stamp, accepted within --max-diff seconds (default: twice\n"
    "     the median ground-truth interval, as evaluate_rpe.py).\n"
    "\n"
    "--json prints one JSON object instead of the text report.\n"
    "Exit status: 0 on success, 1 on bad input or usage (one 'error: ...' line on stderr).\n";

struct UsageError : Error {
  using Error::Error;
};

double parseNumber(const std::string& opt, const std::string& s) {
  const char* c = s.c_str();
  char* end = nullptr;
  errno = 0;
  double v = std::strtod(c, &end);
  if (end == c || *end != '\0' || !std::isfinite(v) || errno == ERANGE) {
    throw UsageError(opt + ": '" + s + "' is not a number");
  }
  return v;
}

Trajectory load(const std::string& path, const char* what) {
  Trajectory t = io::readTrajectory(path);
  if (t.empty()) throw Error(path + ": " + what + " trajectory has no poses (empty file?)");
  return t;
}

std::string f6(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6f", v);
  return buf;
}

// {"pairs", prefix + "rmse" + suffix, ... mean, median, std, min, max}
Json errorStatsJson(const eval::ErrorStats& s, const std::string& prefix, const std::string& suffix = "") {
  Json j{{"pairs", s.count}};
  const std::pair<const char*, double> fields[] = {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median},
                                                   {"std", s.std},   {"min", s.min},   {"max", s.max}};
  for (const auto& f : fields) j[prefix + f.first + suffix] = jsonNumber(f.second);
  return j;
}

// computeAte with the stamp association's error context (the files).
eval::AteResult ateOf(const std::string& gt_path, const std::string& est_path, double max_diff,
                      const Pose* fixed_alignment = nullptr) {
  const Trajectory gt = load(gt_path, "ground-truth");
  const Trajectory est = load(est_path, "estimated");
  try {
    return eval::computeAte(gt, est, max_diff, 0.0, fixed_alignment);
  } catch (const Error& e) {
    throw Error(est_path + " vs " + gt_path + ": " + e.what());
  }
}

int runAte(const std::string& gt_path, const std::string& est_path, double max_diff,
           const std::string& plot, bool json, const std::vector<std::string>& align_with) {
  const Trajectory gt = load(gt_path, "ground-truth");
  const Trajectory est = load(est_path, "estimated");
  Pose fixed = Pose::Identity();
  if (!align_with.empty()) fixed = ateOf(align_with[0], align_with[1], max_diff).alignment;
  const eval::AteResult r = ateOf(gt_path, est_path, max_diff, align_with.empty() ? nullptr : &fixed);
  // Everything that can fail happens before anything is printed.
  if (!plot.empty()) {
    char title[256];
    std::snprintf(title, sizeof(title), "ATE rmse %.4f m  (%zu pairs, max diff %.3g s)", r.stats.rmse,
                  r.stats.count, max_diff);
    eval::writeAtePlot(plot, gt, est, r, title);
  }
  const eval::ErrorStats& s = r.stats;
  std::ostringstream out;
  if (json) {
    out << dumpJson(errorStatsJson(s, ""));
  } else {
    // Same names as evaluate_ate.py --verbose.
    const Eigen::Matrix3d R = r.alignment.linear();
    const Eigen::Vector3d t = r.alignment.translation();
    out << "ground_truth " << gt_path << " (" << gt.size() << " poses)\n"
        << "estimate " << est_path << " (" << est.size() << " poses)\n"
        << "compared_pose_pairs " << s.count << " pairs\n"
        << "absolute_translational_error.rmse " << f6(s.rmse) << " m\n"
        << "absolute_translational_error.mean " << f6(s.mean) << " m\n"
        << "absolute_translational_error.median " << f6(s.median) << " m\n"
        << "absolute_translational_error.std " << f6(s.std) << " m\n"
        << "absolute_translational_error.min " << f6(s.min) << " m\n"
        << "absolute_translational_error.max " << f6(s.max) << " m\n"
        << "alignment (p_gt = R p_est + t):\n";
    for (int i = 0; i < 3; ++i) {
      out << "  R " << f6(R(i, 0)) << " " << f6(R(i, 1)) << " " << f6(R(i, 2)) << "   t " << f6(t[i]) << "\n";
    }
    if (!plot.empty()) out << "plot " << plot << "\n";
  }
  std::cout << out.str() << std::flush;
  return 0;
}

int runRpe(const std::string& gt_path, const std::string& est_path, const eval::RpeOptions& opt,
           bool json) {
  const Trajectory gt = load(gt_path, "ground-truth");
  const Trajectory est = load(est_path, "estimated");
  eval::RpeResult r;
  try {
    r = eval::computeRpe(gt, est, opt);
  } catch (const Error& e) {
    throw Error(est_path + " vs " + gt_path + ": " + e.what());
  }
  const eval::ErrorStats& t = r.trans;
  const eval::ErrorStats& a = r.rot_deg;
  std::ostringstream out;
  if (json) {
    Json j = errorStatsJson(t, "trans_");
    const Json rot = errorStatsJson(a, "rot_", "_deg");
    for (const auto& kv : rot.items())
      if (kv.key() != "pairs") j[kv.key()] = kv.value();
    j["delta"] = jsonNumber(opt.delta);
    j["delta_unit"] = eval::toString(opt.unit);
    j["max_diff"] = jsonNumber(r.max_time_diff);
    out << dumpJson(j);
  } else {
    char delta[32];
    std::snprintf(delta, sizeof(delta), "%g", opt.delta);
    const std::string per = std::string(" per ") + delta +
                            (opt.unit == eval::DeltaUnit::Seconds ? " s" : " frame(s)");
    // Same names as evaluate_rpe.py --verbose.
    out << "ground_truth " << gt_path << " (" << gt.size() << " poses)\n"
        << "estimate " << est_path << " (" << est.size() << " poses)\n"
        << "delta " << delta << " " << eval::toString(opt.unit) << ", max stamp difference "
        << f6(r.max_time_diff) << " s\n"
        << "compared_pose_pairs " << t.count << " pairs\n"
        << "translational_error.rmse " << f6(t.rmse) << " m" << per << "\n"
        << "translational_error.mean " << f6(t.mean) << " m\n"
        << "translational_error.median " << f6(t.median) << " m\n"
        << "translational_error.std " << f6(t.std) << " m\n"
        << "translational_error.min " << f6(t.min) << " m\n"
        << "translational_error.max " << f6(t.max) << " m\n"
        << "rotational_error.rmse " << f6(a.rmse) << " deg" << per << "\n"
        << "rotational_error.mean " << f6(a.mean) << " deg\n"
        << "rotational_error.median " << f6(a.median) << " deg\n"
        << "rotational_error.std " << f6(a.std) << " deg\n"
        << "rotational_error.min " << f6(a.min) << " deg\n"
        << "rotational_error.max " << f6(a.max) << " deg\n";
  }
  std::cout << out.str() << std::flush;
  return 0;
}

int run(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  for (const auto& a : args) {
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    }
  }
  if (args.empty()) throw UsageError("missing command 'ate' or 'rpe'");
  const std::string cmd = args[0];
  if (cmd != "ate" && cmd != "rpe") throw UsageError("unknown command '" + cmd + "'; use 'ate' or 'rpe'");
  std::vector<std::string> pos;
  double max_diff = -1;
  std::string plot;
  std::vector<std::string> align_with;  // GT0 EST0 whose alignment is used
  bool json = false;
  eval::RpeOptions ropt;
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
      return args[++i];
    };
    if (a == "--json") {
      json = true;
    } else if (a == "--max-diff") {
      max_diff = parseNumber(a, value());
      if (!(max_diff > 0)) throw UsageError("--max-diff must be > 0 seconds");
    } else if (a == "--align-with" && cmd == "ate") {
      align_with = {value(), value()};
    } else if (a == "--plot" && cmd == "ate") {
      plot = value();
      if (plot.empty()) throw UsageError("--plot needs a file name");
    } else if (a == "--delta" && cmd == "rpe") {
      ropt.delta = parseNumber(a, value());
      if (!(ropt.delta > 0)) throw UsageError("--delta must be > 0");
    } else if (a == "--delta-unit" && cmd == "rpe") {
      try {
        ropt.unit = eval::parseDeltaUnit(value());
      } catch (const Error& e) {
        throw UsageError(std::string("--delta-unit: ") + e.what());
      }
    } else if (a.size() > 1 && a[0] == '-') {
      throw UsageError("unknown option '" + a + "' for '" + cmd + "'");
    } else {
      pos.push_back(a);
    }
  }
  if (pos.size() != 2) throw UsageError(cmd + " needs exactly two files: GT EST");
  if (cmd == "ate") return runAte(pos[0], pos[1], max_diff > 0 ? max_diff : 0.02, plot, json, align_with);
  ropt.max_time_diff = max_diff > 0 ? max_diff : 0.0;
  return runRpe(pos[0], pos[1], ropt, json);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const UsageError& e) {
    std::cerr << "error: " << e.what() << " (see yolo_slam_eval --help)\n";
    return 1;
  } catch (const Error& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
