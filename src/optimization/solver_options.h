#pragma once
// Solver settings shared by the optimisers of this folder (not installed).
#include <ceres/ceres.h>

namespace yolo_slam {
namespace optimization {

// Levenberg-Marquardt, one thread (deterministic results), no logging.
inline ceres::Solver::Options solverOptions(ceres::LinearSolverType linear_solver, int max_iterations) {
  ceres::Solver::Options o;
  o.linear_solver_type = linear_solver;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.max_num_iterations = max_iterations;
  o.num_threads = 1;
  o.logging_type = ceres::SILENT;
  return o;
}

}  // namespace optimization
}  // namespace yolo_slam
