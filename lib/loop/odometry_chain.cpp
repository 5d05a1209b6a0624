#include "loop/odometry_chain.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>

namespace adit {

void OdometryChain::add(const Eigen::Isometry3d& T_world_keyframe, const Matrix6d& step_covariance) {
  poses_.push_back(T_world_keyframe);
  step_covariances_.push_back(poses_.size() == 1 ? Matrix6d::Zero() : step_covariance);
}

Matrix6d OdometryChain::covarianceBetween(int a, int b) const {
  Matrix6d sum = Matrix6d::Zero();
  if (a < 0 || b >= size() || a >= b) return sum;
  const Eigen::Isometry3d T_b_world = pose(b).inverse();
  for (int k = a + 1; k <= b; ++k) {
    const Matrix6d A = adjoint(T_b_world * pose(k));
    sum += A * step_covariances_[static_cast<std::size_t>(k)] * A.transpose();
  }
  return sum;
}

double loopChi2(const Eigen::Isometry3d& Z, const Eigen::Isometry3d& T_match_query_graph,
                const Matrix6d& chain_covariance, const Matrix6d& loop_covariance) {
  return mahalanobisSquared(boxMinus(Z, T_match_query_graph), chain_covariance + loop_covariance);
}

// The residual's translation part is at least d = sqrt(graph_distance^2 - offset^2) - max_fit_distance long
// (for a partial loop: its part off the free axis, which the graph crosses by at most the offset). Weighing
// translation by 1 and rotation by d^2, chi2 >= (|r_t|^2 + d^2 theta^2) / Lambda, Lambda the largest eigenvalue
// of D M D with D = diag(1, 1, 1, d, d, d), M the full loop's covariance plus the chain's. A partial loop's
// covariance adds any variance along u = (R_fit^T a, 0): chi2 is then at least the minimum over s of the
// quadratic form of r - s u under M, and u can only cover the part of r_t that the rotation residual theta turns
// towards a: |r_t off u|^2 >= d^2 (1 - theta^2). Either way the numerator is at least d^2 max(1, theta^2).
double loopChi2LowerBound(double graph_distance, double max_fit_distance, double partial_axis_offset,
                          const Matrix6d& chain_covariance, const Matrix6d& loop_covariance) {
  const double off_axis2 = graph_distance * graph_distance - partial_axis_offset * partial_axis_offset;
  if (!(off_axis2 > 0.0)) return 0.0;
  const double d = std::sqrt(off_axis2) - max_fit_distance;
  if (!(d > 0.0)) return 0.0;
  Eigen::Matrix<double, 6, 1> scale;
  scale << 1.0, 1.0, 1.0, d, d, d;
  const Matrix6d weighted = scale.asDiagonal() * (chain_covariance + loop_covariance) * scale.asDiagonal();
  const double largest = Eigen::SelfAdjointEigenSolver<Matrix6d>(weighted).eigenvalues().maxCoeff();
  if (!(largest > 0.0) || !std::isfinite(largest)) return 0.0;
  return d * d / largest;
}

double pairChi2(const Eigen::Isometry3d& Z_a, const Eigen::Isometry3d& Z_b, const Eigen::Isometry3d& T_ma_mb,
                const Eigen::Isometry3d& T_qa_qb, const Matrix6d& cycle_covariance) {
  return mahalanobisSquared(boxMinus(Z_a.inverse() * T_ma_mb * Z_b, T_qa_qb), cycle_covariance);
}

}  // namespace adit
