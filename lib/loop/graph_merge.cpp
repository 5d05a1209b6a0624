#include "loop/graph_merge.hpp"

namespace adit {
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
  for (const PoseGraphEdge& e : graph.edges()) {
    const int from = out.new_index[static_cast<std::size_t>(e.from)], to = out.new_index[static_cast<std::size_t>(e.to)];
    if (from < 0 || to < 0) continue;
    PoseGraphEdge copy = e;
    copy.from = from;
    copy.to = to;
    out.graph.addEdge(copy);
  }
  return out;
}

}  // namespace adit
