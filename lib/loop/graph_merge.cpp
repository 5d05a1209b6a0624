#include "loop/graph_merge.hpp"

#include "loop/se3.hpp"

#include <Eigen/Cholesky>

#include <limits>
#include <map>
#include <utility>

namespace adit {
namespace {

double logDeterminant(const Matrix6d& information) {
  const Eigen::LLT<Matrix6d> llt(information);
  if (llt.info() != Eigen::Success) return -std::numeric_limits<double>::infinity();
  return 2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
}

}  // namespace

MergedGraph mergeOutNodes(const PoseGraph& graph, const OdometryChain& chain, std::vector<bool> keep) {
  const int n = graph.size();
  keep.resize(static_cast<std::size_t>(n), true);
  if (n > 0) keep.front() = keep.back() = true;
  MergedGraph out;
  out.new_index.assign(static_cast<std::size_t>(n), -1);

  // Nodes and chain steps; a kept node after a removed run gets the run's summed step.
  std::vector<int> kept;
  for (int k = 0; k < n; ++k) {
    if (!keep[static_cast<std::size_t>(k)]) continue;
    out.new_index[static_cast<std::size_t>(k)] = out.graph.addNode(graph.pose(k));
    const Matrix6d step = kept.empty() ? chain.stepCovariance(k) : chain.covarianceBetween(kept.back(), k);
    out.chain.add(chain.pose(k), step);
    kept.push_back(k);
  }

  // Odometry edges in chain order: the original where both ends stay, one merged edge across each removed run.
  for (std::size_t i = 1; i < kept.size(); ++i) {
    const int a = kept[i - 1], b = kept[i];
    const int na = static_cast<int>(i) - 1, nb = static_cast<int>(i);
    if (b == a + 1) continue;  // copied below with the other edges, in their order
    out.graph.addOdometryEdge(na, nb, graph.pose(a).inverse() * graph.pose(b),
                              chain.covarianceBetween(a, b).inverse());
  }
  std::vector<int> kept_at_or_before(static_cast<std::size_t>(n), 0);
  for (int k = 1; k < n; ++k)
    kept_at_or_before[static_cast<std::size_t>(k)] = keep[static_cast<std::size_t>(k)] ? k : kept_at_or_before[static_cast<std::size_t>(k) - 1];
  // A moved loop landing on two nodes that another loop already joins keeps the more certain of the two only:
  // a patrol's revisit loops all land on a few kept nodes, and their errors are the same stretch of chain, so
  // adding them up would be over-confident; one edge per pair also keeps the graph's size with the map's.
  std::vector<PoseGraphEdge> edges;
  std::map<std::pair<int, int>, std::size_t> loop_between;  // (from, to) -> its loop in edges
  for (const PoseGraphEdge& e : graph.edges()) {
    PoseGraphEdge copy = e;
    copy.from = out.new_index[static_cast<std::size_t>(e.from)];
    copy.to = out.new_index[static_cast<std::size_t>(e.to)];
    if (copy.from >= 0 && copy.to >= 0) {
      if (e.robust) loop_between.emplace(std::make_pair(copy.from, copy.to), edges.size());
      edges.push_back(copy);
      continue;
    }
    if (!e.robust) continue;
    const int a = kept_at_or_before[static_cast<std::size_t>(e.from)], b = kept_at_or_before[static_cast<std::size_t>(e.to)];
    std::optional<PoseGraphEdge> moved = reanchoredLoop(graph, chain, e, a, b);
    if (!moved) continue;
    moved->from = out.new_index[static_cast<std::size_t>(a)];
    moved->to = out.new_index[static_cast<std::size_t>(b)];
    const auto [it, first] = loop_between.emplace(std::make_pair(moved->from, moved->to), edges.size());
    if (first) {
      edges.push_back(*moved);
    } else if (logDeterminant(moved->information) > logDeterminant(edges[it->second].information)) {
      edges[it->second] = *moved;
    }
  }
  for (const PoseGraphEdge& e : edges) out.graph.addEdge(e);
  return out;
}

std::optional<PoseGraphEdge> reanchoredLoop(const PoseGraph& graph, const OdometryChain& chain,
                                            const PoseGraphEdge& e, int a, int b) {
  if (a == b || a > e.from || b > e.to) return std::nullopt;
  const Eigen::LLT<Matrix6d> loop_information(e.information);
  if (loop_information.info() != Eigen::Success) return std::nullopt;
  const Eigen::Isometry3d T_a_from = graph.pose(a).inverse() * graph.pose(e.from);
  const Eigen::Isometry3d T_b_to = graph.pose(b).inverse() * graph.pose(e.to);
  const Eigen::Isometry3d T_from_b = e.T_from_to * T_b_to.inverse();
  // Right perturbations moved to the end of T_a_from * Z * T_to_b: X Exp(d) Y = X Y Exp(adjoint(Y^-1) d).
  // T_b_to's own perturbation enters T_to_b negated on the left, so it lands where Z's does.
  const Matrix6d A_from = adjoint(T_from_b.inverse());
  const Matrix6d A_to = adjoint(T_b_to);
  const Matrix6d covariance = A_from * chain.covarianceBetween(a, e.from) * A_from.transpose() +
                              A_to * (loop_information.solve(Matrix6d::Identity()) + chain.covarianceBetween(b, e.to)) *
                                  A_to.transpose();
  const Eigen::LLT<Matrix6d> llt(0.5 * (covariance + covariance.transpose()));
  if (llt.info() != Eigen::Success) return std::nullopt;
  PoseGraphEdge out = e;
  out.from = a;
  out.to = b;
  out.T_from_to = T_a_from * T_from_b;
  const Matrix6d information = llt.solve(Matrix6d::Identity());
  out.information = 0.5 * (information + information.transpose());
  return out;
}

}  // namespace adit
