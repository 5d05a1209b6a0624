#include "registration/pose_increment.hpp"

#include "core/geometry.hpp"

namespace adit {

Eigen::Isometry3d applyIncrement(const Eigen::Isometry3d& T0, const Vector6d& xi) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = T0.linear() * expRotation(xi.tail<3>());
  T.translation() = T0.translation() + T0.linear() * xi.head<3>();
  return T;
}

Vector6d incrementBetween(const Eigen::Isometry3d& T0, const Eigen::Isometry3d& T) {
  Vector6d xi;
  xi.head<3>() = T0.linear().transpose() * (T.translation() - T0.translation());
  xi.tail<3>() = logRotation(T0.linear().transpose() * T.linear());
  return xi;
}

Eigen::Isometry3d scaleMotion(const Eigen::Isometry3d& delta, double s) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = expRotation(s * logRotation(delta.linear()));
  out.translation() = s * delta.translation();
  return out;
}

bool hasConverged(const Eigen::Isometry3d& before, const Eigen::Isometry3d& after) {
  const Vector6d xi = incrementBetween(before, after);
  return xi.head<3>().norm() < 1e-3 && xi.tail<3>().norm() < 1.75e-4;
}

bool isFinitePose(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

}  // namespace adit
