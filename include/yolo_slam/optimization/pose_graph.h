#pragma once
// SE3 pose-graph (essential-graph) optimisation for loop closing: nodes are camera poses T_wc,
// edges are measured relative poses. RGB-D has metric scale, so SE3 replaces ORB-SLAM2's Sim3.
#include "yolo_slam/common/geometry.h"

#include <map>
#include <set>
#include <vector>

namespace yolo_slam {
namespace optimization {

struct PoseGraphEdge {
  long from, to;
  Pose T_from_to;       // measured T_from_to = T_w_from^-1 * T_w_to
  double weight = 1;    // scales the information of all 6 residuals (> 0)
};

struct PoseGraphResult {
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;  // 0.5 * sum of weighted squared residuals
};

// Residual per edge (tangent-space error of E = T_from_to_meas^-1 * T_from^-1 * T_to):
//   sqrt(weight) * [ translation of E (metres) ; 2 * vec(q_E) (~ rotation vector, radians) ].
// Nodes in `fixed` are held constant (fix at least one, else the whole graph may drift).
// Nodes not referenced by any edge are untouched. Throws yolo_slam::Error when an edge names a
// node missing from T_wc, has a non-finite pose or a weight <= 0.
PoseGraphResult optimizePoseGraph(std::map<long, Pose>& T_wc, const std::vector<PoseGraphEdge>& edges,
                                  const std::set<long>& fixed, int iterations = 20);

}  // namespace optimization
}  // namespace yolo_slam
