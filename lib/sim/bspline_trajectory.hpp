// The ground-truth trajectory T_world_lidar(t): a uniform cumulative cubic B-spline on SO(3) x R^3.
//
// Why a spline: every output of the simulator (each lidar firing's pose, the IMU's angular velocity and specific
// force, the ground-truth file) is read off this one C2-smooth function, and its derivatives are exact
// (analytic), so the IMU is consistent with the lidar motion to machine precision.
//   position:  p(t) = sum_j B_j(u) P_{i+j}                     (uniform cubic B-spline)
//   rotation:  R(t) = R_i * prod_{j=1..3} Exp(lambda_j(u) * Log(R_{i+j-1}^T R_{i+j}))   (cumulative form)
// with u = (t - t_i) / dt. Angular velocity is in the body (lidar) frame, acceleration in the world frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace adit::sim {

struct TrajectoryState {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // T_world_body
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          // world frame (m/s)
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();      // world frame (m/s^2), without gravity
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // body frame (rad/s)
};

class BSplineTrajectory {
 public:
  BSplineTrajectory() = default;
  // Control pose k belongs to time t0 + (k - 1) * dt (the spline passes near it); valid for
  // t in [t0, t0 + (n - 3) * dt]. Needs n >= 4 controls; outside the valid range t is clamped.
  BSplineTrajectory(double t0, double dt, std::vector<Eigen::Isometry3d> controls);

  Eigen::Isometry3d pose(double t) const;
  TrajectoryState state(double t) const;
  double startTime() const { return t0_; }
  double endTime() const { return t0_ + (static_cast<double>(positions_.size()) - 3.0) * dt_; }
  double knotSpacing() const { return dt_; }

 private:
  // Segment index and normalised time u in [0, 1].
  void locate(double t, int& i, double& u) const;
  double t0_ = 0.0, dt_ = 1.0;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<Eigen::Matrix3d> rotations_;
  std::vector<Eigen::Vector3d> deltas_;  // deltas_[k] = Log(R_{k-1}^T R_k), k >= 1
};

// SO(3) exponential and logarithm (Rodrigues), accurate near zero angle.
Eigen::Matrix3d so3Exp(const Eigen::Vector3d& w);
Eigen::Vector3d so3Log(const Eigen::Matrix3d& R);

}  // namespace adit::sim
