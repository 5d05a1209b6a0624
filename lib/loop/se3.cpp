#include "loop/se3.hpp"

#include "core/geometry.hpp"

#include <Eigen/Cholesky>

#include <limits>

namespace adit {

Vector6d boxMinus(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Isometry3d delta = b.inverse() * a;
  Vector6d out;
  out.head<3>() = delta.translation();
  out.tail<3>() = logRotation(delta.linear());
  return out;
}

Matrix6d adjoint(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d t = T.translation();
  Eigen::Matrix3d t_hat;
  t_hat << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  Matrix6d A = Matrix6d::Zero();
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = t_hat * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

bool isValidCovariance(const Matrix6d& covariance) {
  if (!covariance.allFinite()) return false;
  if (!covariance.isApprox(covariance.transpose(), 1e-6)) return false;
  return covariance.llt().info() == Eigen::Success;
}

double mahalanobisSquared(const Vector6d& e, const Matrix6d& S) {
  const Eigen::LLT<Matrix6d> llt(S);
  if (llt.info() != Eigen::Success || !e.allFinite()) return std::numeric_limits<double>::infinity();
  return e.dot(llt.solve(e));
}

Eigen::Isometry3d orthonormal(const Eigen::Isometry3d& T) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  out.translation() = T.translation();
  return out;
}

}  // namespace adit
