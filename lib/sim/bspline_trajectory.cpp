#include "sim/bspline_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace adit::sim {

Eigen::Matrix3d so3Exp(const Eigen::Vector3d& w) {
  const double theta2 = w.squaredNorm();
  Eigen::Matrix3d W;
  W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  double a, b;  // sin(theta)/theta, (1 - cos(theta))/theta^2
  if (theta2 < 1e-10) {
    a = 1.0 - theta2 / 6.0;
    b = 0.5 - theta2 / 24.0;
  } else {
    const double theta = std::sqrt(theta2);
    a = std::sin(theta) / theta;
    b = (1.0 - std::cos(theta)) / theta2;
  }
  return Eigen::Matrix3d::Identity() + a * W + b * W * W;
}

Eigen::Vector3d so3Log(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

BSplineTrajectory::BSplineTrajectory(double t0, double dt, std::vector<Eigen::Isometry3d> controls)
    : t0_(t0), dt_(dt) {
  if (controls.size() < 4 || !(dt > 0.0)) throw std::invalid_argument("BSplineTrajectory: needs >= 4 controls, dt > 0");
  positions_.reserve(controls.size());
  rotations_.reserve(controls.size());
  deltas_.assign(controls.size(), Eigen::Vector3d::Zero());
  for (std::size_t k = 0; k < controls.size(); ++k) {
    positions_.push_back(controls[k].translation());
    rotations_.push_back(controls[k].linear());
    if (k > 0) deltas_[k] = so3Log(rotations_[k - 1].transpose() * rotations_[k]);
  }
}

void BSplineTrajectory::locate(double t, int& i, double& u) const {
  const int segments = static_cast<int>(positions_.size()) - 3;
  const double x = std::clamp((t - t0_) / dt_, 0.0, static_cast<double>(segments));
  i = std::min(static_cast<int>(std::floor(x)), segments - 1);
  u = x - i;
}

Eigen::Isometry3d BSplineTrajectory::pose(double t) const {
  int i;
  double u;
  locate(t, i, u);
  const double u2 = u * u, u3 = u2 * u;
  const double b[4] = {(1 - u) * (1 - u) * (1 - u) / 6, (3 * u3 - 6 * u2 + 4) / 6, (-3 * u3 + 3 * u2 + 3 * u + 1) / 6,
                       u3 / 6};
  const double lambda[3] = {(5 + 3 * u - 3 * u2 + u3) / 6, (1 + 3 * u + 3 * u2 - 2 * u3) / 6, u3 / 6};
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R = rotations_[i];
  for (int j = 1; j <= 3; ++j) R = R * so3Exp(lambda[j - 1] * deltas_[i + j]);
  T.linear() = R;
  T.translation() = b[0] * positions_[i] + b[1] * positions_[i + 1] + b[2] * positions_[i + 2] + b[3] * positions_[i + 3];
  return T;
}

TrajectoryState BSplineTrajectory::state(double t) const {
  int i;
  double u;
  locate(t, i, u);
  const double u2 = u * u, u3 = u2 * u;
  const double b[4] = {(1 - u) * (1 - u) * (1 - u) / 6, (3 * u3 - 6 * u2 + 4) / 6, (-3 * u3 + 3 * u2 + 3 * u + 1) / 6,
                       u3 / 6};
  const double db[4] = {-(1 - u) * (1 - u) / 2, 1.5 * u2 - 2 * u, -1.5 * u2 + u + 0.5, u2 / 2};
  const double ddb[4] = {1 - u, 3 * u - 2, 1 - 3 * u, u};
  const double lambda[3] = {(5 + 3 * u - 3 * u2 + u3) / 6, (1 + 3 * u + 3 * u2 - 2 * u3) / 6, u3 / 6};
  const double dlambda[3] = {(3 - 6 * u + 3 * u2) / 6, (3 + 6 * u - 6 * u2) / 6, u2 / 2};

  TrajectoryState s;
  Eigen::Matrix3d R = rotations_[i];
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  for (int j = 1; j <= 3; ++j) {
    const Eigen::Matrix3d A = so3Exp(lambda[j - 1] * deltas_[i + j]);
    R = R * A;
    // Body rate of R_(j) = R_(j-1) A_j: A_j^T omega_(j-1) + d/dt(lambda_j) * delta_j.
    omega = A.transpose() * omega + (dlambda[j - 1] / dt_) * deltas_[i + j];
  }
  s.pose.linear() = R;
  s.angular_velocity = omega;
  s.pose.translation().setZero();
  for (int j = 0; j < 4; ++j) {
    s.pose.translation() += b[j] * positions_[i + j];
    s.velocity += (db[j] / dt_) * positions_[i + j];
    s.acceleration += (ddb[j] / (dt_ * dt_)) * positions_[i + j];
  }
  return s;
}

}  // namespace adit::sim
