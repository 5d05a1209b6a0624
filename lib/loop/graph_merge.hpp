// Nodes merged out of the pose graph and the odometry chain: what keeps a patrol's memory flat.
//
// A robot that drives mapped roadway for hours adds a keyframe a metre, and each one that only revisits the
// map (no cloud, no Scan Context) still costs a graph node, an odometry edge and a chain step. Once such a
// keyframe is older than the loop search's window nothing refers to it any more but the graph: it is merged
// out. Each run of removed nodes between two kept nodes a and b becomes one edge a -> b
//   - measured as the graph's current estimate X_a^-1 X_b: the corrections the run's loops made are kept, so
//     merging moves no pose (the loops themselves go with the run: their information is spent), and
//   - weighted by the odometry chain's covariance of a -> b (the sum of the run's steps): what the keyframes
//     between them knew about the relative pose without those loops, so the edge is never over-confident.
// Loop edges with both ends kept are kept; every other edge touching a removed node goes.
#pragma once

#include "loop/odometry_chain.hpp"
#include "loop/pose_graph.hpp"

#include <vector>

namespace adit {

struct MergedGraph {
  PoseGraph graph;
  OdometryChain chain;
  std::vector<int> new_index;  // [old node]: its index in the merged graph, -1 if merged out
};

// keep[k]: node k stays. Node 0 and the newest node always stay (the graph's frame and where the next
// keyframe attaches); graph and chain must have the same nodes, consecutive nodes joined by odometry edges.
MergedGraph mergeOutNodes(const PoseGraph& graph, const OdometryChain& chain, std::vector<bool> keep);

}  // namespace adit
