#include "loop/odometry_chain.hpp"

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

double pairChi2(const Eigen::Isometry3d& Z_a, const Eigen::Isometry3d& Z_b, const Eigen::Isometry3d& T_ma_mb,
                const Eigen::Isometry3d& T_qa_qb, const Matrix6d& cycle_covariance) {
  return mahalanobisSquared(boxMinus(Z_a.inverse() * T_ma_mb * Z_b, T_qa_qb), cycle_covariance);
}

}  // namespace adit
