#include "loop/pose_graph.hpp"

#include "loop/se3.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <memory>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace adit {
namespace {

// Residual of one relative-pose measurement T_ab: the right-perturbation difference between the estimate
// T_a^-1 T_b and the measurement, whitened by the square root of the information.
class RelativePoseError {
 public:
  RelativePoseError(const Eigen::Isometry3d& T_ab, const Matrix6d& sqrt_information)
      : p_ab_(T_ab.translation()), q_ab_(Eigen::Quaterniond(T_ab.linear()).normalized()), sqrt_info_(sqrt_information) {}

  template <class T>
  bool operator()(const T* p_a_ptr, const T* q_a_ptr, const T* p_b_ptr, const T* q_b_ptr, T* residual_ptr) const {
    Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_a(p_a_ptr), p_b(p_b_ptr);
    Eigen::Map<const Eigen::Quaternion<T>> q_a(q_a_ptr), q_b(q_b_ptr);
    const Eigen::Quaternion<T> q_a_inv = q_a.conjugate();
    const Eigen::Matrix<T, 3, 1> p_ab_est = q_a_inv * (p_b - p_a);
    const Eigen::Quaternion<T> q_ab_est = q_a_inv * q_b;
    const Eigen::Quaternion<T> q_meas_inv = q_ab_.conjugate().template cast<T>();
    // delta = measurement^-1 * estimate; its translation and (small-angle) rotation vector.
    const Eigen::Quaternion<T> dq = q_meas_inv * q_ab_est;
    Eigen::Matrix<T, 6, 1> r;
    r.template head<3>() = q_meas_inv * (p_ab_est - p_ab_.template cast<T>());
    r.template tail<3>() = T(2.0) * dq.vec();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> residual(residual_ptr);
    residual = sqrt_info_.template cast<T>() * r;
    return true;
  }

 private:
  Eigen::Vector3d p_ab_;
  Eigen::Quaterniond q_ab_;
  Matrix6d sqrt_info_;
};

struct NodeState {
  Eigen::Vector3d p;
  Eigen::Quaterniond q;
};

// Ceres' num_threads does not reach the sparse Cholesky below it: CHOLMOD (SuiteSparse) opens OpenMP parallel
// regions of its own fixed team size (4) once a supernodal factorisation is large enough, and OpenMP keeps
// those threads for the life of the process (a two-hour live soak: the loop closer went 4 -> 7 threads at
// 1 h 48 min; a 1,000-node lattice does it in a test), busy-waiting after each region. A team size clause overrides
// omp_set_num_threads, so parallel regions are made inactive instead (zero active levels: a region runs on
// the thread that opens it). The setting belongs to the calling thread, so it is made here, on whichever
// thread solves.
void solveOnThisThreadOnly() {
#ifdef _OPENMP
  omp_set_max_active_levels(0);
#endif
}

}  // namespace

int PoseGraph::addNode(const Eigen::Isometry3d& initial_pose) {
  poses_.push_back(initial_pose);
  return size() - 1;
}

bool PoseGraph::addEdge(const PoseGraphEdge& edge) {
  if (edge.from < 0 || edge.to < 0 || edge.from >= size() || edge.to >= size() || edge.from == edge.to) return false;
  if (!edge.T_from_to.matrix().allFinite()) return false;
  PoseGraphEdge e = edge;
  if (!isValidCovariance(e.information)) e.information = Matrix6d::Identity();
  edges_.push_back(e);
  return true;
}

bool PoseGraph::addOdometryEdge(int from, int to, const Eigen::Isometry3d& T_from_to, const Matrix6d& information) {
  return addEdge({from, to, T_from_to, information, false});
}

bool PoseGraph::addLoopEdge(int from, int to, const Eigen::Isometry3d& T_from_to, const Matrix6d& information) {
  return addEdge({from, to, T_from_to, information, true});
}

PoseGraphReport PoseGraph::optimize(const PoseGraphConfig& config) {
  PoseGraphReport report;
  if (size() < 2 || edges_.empty()) {
    report.solved = true;
    return report;
  }
  std::vector<NodeState> state(poses_.size());
  for (std::size_t i = 0; i < poses_.size(); ++i) {
    state[i].p = poses_[i].translation();
    state[i].q = Eigen::Quaterniond(poses_[i].linear()).normalized();
  }
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::CauchyLoss loop_loss(config.loop_loss_scale);  // owned here, not by the problem

  const auto fixed = [&](int id) { return id < std::max(1, config.fixed_nodes); };
  for (const PoseGraphEdge& e : edges_) {
    if (fixed(e.from) && fixed(e.to)) continue;  // nothing it could move
    const Matrix6d sqrt_info = e.information.llt().matrixU();
    auto* cost = new ceres::AutoDiffCostFunction<RelativePoseError, 6, 3, 4, 3, 4>(
        new RelativePoseError(e.T_from_to, sqrt_info));
    NodeState& a = state[static_cast<std::size_t>(e.from)];
    NodeState& b = state[static_cast<std::size_t>(e.to)];
    problem.AddResidualBlock(cost, e.robust ? &loop_loss : nullptr, a.p.data(), a.q.coeffs().data(), b.p.data(),
                             b.q.coeffs().data());
  }
  for (NodeState& s : state)
    if (problem.HasParameterBlock(s.q.coeffs().data())) problem.SetManifold(s.q.coeffs().data(), &quaternion_manifold);
  for (std::size_t i = 0; i < state.size() && fixed(static_cast<int>(i)); ++i) {
    if (!problem.HasParameterBlock(state[i].p.data())) continue;
    problem.SetParameterBlockConstant(state[i].p.data());
    problem.SetParameterBlockConstant(state[i].q.coeffs().data());
  }
  if (problem.NumResidualBlocks() == 0) {
    report.solved = true;
    return report;
  }

  ceres::Solver::Options options;
  options.max_num_iterations = config.max_iterations;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.num_threads = 1;  // deterministic
  solveOnThisThreadOnly();
  // A pose graph warm-started from odometry is well posed: start close to Gauss-Newton (fewer iterations).
  options.initial_trust_region_radius = 1e8;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  report.solved = summary.IsSolutionUsable();
  report.iterations = static_cast<int>(summary.iterations.size());
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;
  if (!report.solved) return report;
  for (std::size_t i = 0; i < poses_.size(); ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = state[i].q.normalized().toRotationMatrix();
    T.translation() = state[i].p;
    poses_[i] = T;
  }
  return report;
}

}  // namespace adit
