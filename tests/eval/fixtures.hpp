// Hand-made trajectories with known geometry for the evaluation tests.
#pragma once

#include "core/types.hpp"

#include <cmath>
#include <cstdint>
#include <string>

#include <unistd.h>

namespace adit::eval::test {

inline Eigen::Isometry3d poseAt(const Eigen::Vector3d& p, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = p;
  return T;
}

// A winding 3D path (not on a line or a plane, so Umeyama is well posed), heading along its tangent,
// n poses at 10 Hz starting at t0_s.
inline Trajectory windingPath(int n, double t0_s = 100.0) {
  Trajectory out;
  for (int k = 0; k < n; ++k) {
    const double s = 0.5 * k;
    const Eigen::Vector3d p(s, 5.0 * std::sin(0.05 * k), 0.3 * std::sin(0.02 * k));
    const double yaw = std::atan2(0.25 * std::cos(0.05 * k), 0.5);
    out.push_back({toUtime(t0_s + 0.1 * k), poseAt(p, yaw)});
  }
  return out;
}

// n poses on a circle of radius r around the origin in the z = h plane.
inline Trajectory circle(int n, double r, double h = 0.0) {
  Trajectory out;
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * M_PI * k / n;
    out.push_back({toUtime(0.1 * k), poseAt(Eigen::Vector3d(r * std::cos(a), r * std::sin(a), h + 0.5 * std::sin(3 * a)),
                                            a + M_PI / 2)});
  }
  return out;
}

// Straight line along +x with `step_m` between poses, identity orientation.
inline Trajectory line(int n, double step_m) {
  Trajectory out;
  for (int k = 0; k < n; ++k) out.push_back({toUtime(0.1 * k), poseAt(Eigen::Vector3d(step_m * k, 0, 0), 0.0)});
  return out;
}

// Left-multiply every pose by a similarity (p' = s R p + t, R' = R R_p).
inline Trajectory transformed(const Trajectory& in, const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double s = 1.0) {
  Trajectory out = in;
  for (StampedPose& p : out) {
    p.pose.translation() = s * R * p.pose.translation() + t;
    p.pose.linear() = R * p.pose.linear();
  }
  return out;
}

inline std::string tempPath(const std::string& name) {
  return std::string("/tmp/adit_test_eval_") + std::to_string(::getpid()) + "_" + name;
}

}  // namespace adit::eval::test
