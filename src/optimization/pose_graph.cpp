#include "yolo_slam/optimization/pose_graph.h"

#include "yolo_slam/common/error.h"

#include "solver_options.h"

#include <ceres/ceres.h>

#include <array>
#include <cmath>
#include <unordered_map>

namespace yolo_slam {
namespace optimization {

namespace {

// Parameters per node: quaternion q_wc (Eigen order x y z w) and translation t_wc.
struct RelativePoseError {
  RelativePoseError(const Pose& T_ab, double weight)
      : q_ab_inv(Eigen::Quaterniond(T_ab.linear()).normalized().conjugate()),
        t_ab(T_ab.translation()),
        sqrt_w(std::sqrt(weight)) {}

  template <typename T>
  bool operator()(const T* qa_p, const T* ta_p, const T* qb_p, const T* tb_p, T* r) const {
    Eigen::Map<const Eigen::Quaternion<T>> qa(qa_p), qb(qb_p);
    Eigen::Map<const Eigen::Matrix<T, 3, 1>> ta(ta_p), tb(tb_p);
    const Eigen::Quaternion<T> qa_inv = qa.conjugate();
    // Estimated relative pose T_ab = T_wa^-1 T_wb.
    const Eigen::Quaternion<T> q_est = qa_inv * qb;
    const Eigen::Matrix<T, 3, 1> t_est = qa_inv * (tb - ta);
    // Error E = T_ab_meas^-1 * T_ab_est.
    const Eigen::Quaternion<T> q_meas_inv = q_ab_inv.template cast<T>();
    Eigen::Quaternion<T> dq = q_meas_inv * q_est;
    const Eigen::Matrix<T, 3, 1> dt = q_meas_inv * (t_est - t_ab.template cast<T>());
    // q and -q are the same rotation: take the short way round.
    const T sign = dq.w() < T(0) ? T(-1) : T(1);
    for (int k = 0; k < 3; ++k) {
      r[k] = T(sqrt_w) * dt[k];
      r[3 + k] = T(2.0 * sqrt_w) * sign * dq.vec()[k];
    }
    return true;
  }

  Eigen::Quaterniond q_ab_inv;
  Eigen::Vector3d t_ab;
  double sqrt_w;
};

struct Node {
  std::array<double, 4> q;
  std::array<double, 3> t;
};

// The nodes the edges touch, at their T_wc; throws on a bad edge or node.
std::unordered_map<long, Node> graphNodes(const std::map<long, Pose>& T_wc, const std::vector<PoseGraphEdge>& edges) {
  std::unordered_map<long, Node> nodes;
  for (size_t i = 0; i < edges.size(); ++i) {
    const PoseGraphEdge& e = edges[i];
    if (!(e.weight > 0) || !std::isfinite(e.weight) || !e.T_from_to.matrix().allFinite()) {
      throw Error("optimizePoseGraph: edge " + std::to_string(i) + " (" + std::to_string(e.from) +
                  " -> " + std::to_string(e.to) + ") has a non-finite pose or a weight <= 0");
    }
    for (long id : {e.from, e.to}) {
      if (nodes.count(id)) continue;
      auto it = T_wc.find(id);
      if (it == T_wc.end()) {
        throw Error("optimizePoseGraph: edge " + std::to_string(i) + " refers to node " +
                    std::to_string(id) + " which has no pose");
      }
      if (!it->second.matrix().allFinite()) {
        throw Error("optimizePoseGraph: node " + std::to_string(id) + " has a non-finite pose");
      }
      Eigen::Quaterniond q(it->second.linear());
      q.normalize();
      Node n{{q.x(), q.y(), q.z(), q.w()},
             {it->second.translation().x(), it->second.translation().y(), it->second.translation().z()}};
      nodes.emplace(id, n);
    }
  }
  return nodes;
}

}  // namespace

PoseGraphResult optimizePoseGraph(std::map<long, Pose>& T_wc, const std::vector<PoseGraphEdge>& edges,
                                  const std::set<long>& fixed, int iterations) {
  PoseGraphResult res;
  std::unordered_map<long, Node> nodes = graphNodes(T_wc, edges);
  if (edges.empty() || iterations <= 0) return res;

  ceres::Problem::Options popts;
  popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(popts);
  ceres::EigenQuaternionManifold quaternion_manifold;
  for (auto& kv : nodes) {
    problem.AddParameterBlock(kv.second.q.data(), 4, &quaternion_manifold);
    problem.AddParameterBlock(kv.second.t.data(), 3);
    if (fixed.count(kv.first)) {
      problem.SetParameterBlockConstant(kv.second.q.data());
      problem.SetParameterBlockConstant(kv.second.t.data());
    }
  }
  for (const PoseGraphEdge& e : edges) {
    Node& a = nodes[e.from];
    Node& b = nodes[e.to];
    auto* cost = new ceres::AutoDiffCostFunction<RelativePoseError, 6, 4, 3, 4, 3>(
        new RelativePoseError(e.T_from_to, e.weight));
    problem.AddResidualBlock(cost, nullptr, a.q.data(), a.t.data(), b.q.data(), b.t.data());
  }

  const ceres::Solver::Options sopts = solverOptions(
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ? ceres::SPARSE_NORMAL_CHOLESKY
                                                                          : ceres::DENSE_QR,
      iterations);
  ceres::Solver::Summary summary;
  ceres::Solve(sopts, &problem, &summary);
  res.iterations = std::max(0, static_cast<int>(summary.iterations.size()) - 1);
  res.initial_cost = summary.initial_cost;
  res.final_cost = summary.final_cost;

  for (const auto& kv : nodes) {
    if (fixed.count(kv.first)) continue;
    const Node& n = kv.second;
    Pose T = makePose(Eigen::Quaterniond(n.q[3], n.q[0], n.q[1], n.q[2]),
                      Eigen::Vector3d(n.t[0], n.t[1], n.t[2]));
    if (T.matrix().allFinite()) T_wc[kv.first] = T;
  }
  return res;
}

}  // namespace optimization
}  // namespace yolo_slam
