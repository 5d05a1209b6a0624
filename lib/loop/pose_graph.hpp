// SE(3) pose graph over keyframes, optimised with Ceres: relative-pose residuals, quaternion manifold,
// first node fixed, odometry edges weighted by their information, loop edges behind a robust loss.
#pragma once

#include "core/shared_append_vector.hpp"
#include "core/types.hpp"

#include <iosfwd>
#include <string>
#include <vector>

namespace adit {

struct PoseGraphConfig {
  // Ceres Levenberg-Marquardt iterations per optimize(); a warm-started graph converges in a handful.
  int max_iterations = 50;
  // Cauchy loss scale on loop edges, in whitened units (loop standard deviations). Accepted loops already passed
  // verification and both gates, and a valid loop removing metres of drift starts 10-20 sigma (of its own
  // few-cm noise) away, so a small scale would silence exactly the loops we want; 10 keeps those near their
  // quadratic region while a gross false loop (20 m off = ~400 sigma) pulls with ~1/40 of its weight.
  double loop_loss_scale = 10.0;
  // Nodes 0 .. fixed_nodes-1 are held where they are (at least node 0: the graph's frame). A map bundle being
  // extended (map/bundle_extend.hpp) holds every node of the saved map and moves only the new session's.
  int fixed_nodes = 1;
};

struct PoseGraphEdge {
  int from = -1;  // node a
  int to = -1;    // node b
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();  // measured T_a_b
  Matrix6d information = Matrix6d::Identity();  // tangent order (t, r), right perturbation of T_a_b
  bool robust = false;  // loop edges: robust loss
};

struct PoseGraphReport {
  bool solved = false;  // Ceres returned a usable solution
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
};

class PoseGraph {
 public:
  // Returns the new node's id (0, 1, 2, ... in order). Node 0 is held fixed.
  int addNode(const Eigen::Isometry3d& initial_pose);
  // Edges between existing nodes; information must be symmetric positive definite (else it is replaced by
  // identity and the edge is still added). Returns false for unknown node ids or non-finite measurements.
  bool addOdometryEdge(int from, int to, const Eigen::Isometry3d& T_from_to, const Matrix6d& information);
  bool addLoopEdge(int from, int to, const Eigen::Isometry3d& T_from_to, const Matrix6d& information);
  bool addEdge(const PoseGraphEdge& edge);

  PoseGraphReport optimize(const PoseGraphConfig& config = {});

  int size() const { return static_cast<int>(poses_.size()); }
  const Eigen::Isometry3d& pose(int id) const { return poses_[static_cast<std::size_t>(id)]; }
  const std::vector<Eigen::Isometry3d>& poses() const { return poses_; }
  void setPose(int id, const Eigen::Isometry3d& pose) { poses_[static_cast<std::size_t>(id)] = pose; }
  const SharedAppendVector<PoseGraphEdge>& edges() const { return edges_; }

 private:
  std::vector<Eigen::Isometry3d> poses_;  // copied by a copy of the graph (an optimisation moves them all)
  SharedAppendVector<PoseGraphEdge> edges_;  // shared by copies (a loop job's snapshot): edges never change
};

// g2o text format (VERTEX_SE3:QUAT id x y z qx qy qz qw; EDGE_SE3:QUAT a b x y z qx qy qz qw + the 21 upper-
// triangular entries of the information, whose rotation part g2o expresses in quaternion-vector units; FIX 0).
// Edges between non-consecutive ids load as robust (loop) edges.
void writeG2o(const PoseGraph& graph, std::ostream& out);
// Returns false (graph untouched) on a malformed line, unknown vertex or non-contiguous vertex ids.
bool readG2o(std::istream& in, PoseGraph& graph);
// File wrappers; saving writes "<path>.tmp" and renames it over path, so readers never see a partial file.
bool saveG2o(const PoseGraph& graph, const std::string& path);
bool loadG2o(const std::string& path, PoseGraph& graph);

}  // namespace adit
