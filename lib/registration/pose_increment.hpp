// The local pose parameterisation used by both registration stages.
//
// A pose near a linearisation point T0 is written T = T0 * Exp(xi), xi = (rho, phi) in tangent order
// (tx ty tz rx ry rz), expressed in T0's lidar frame: R = R0 * exp(phi), t = t0 + R0 * rho. Optimising xi
// (re-linearising at every outer iteration) is an SE(3) "manifold of our own": the Jacobian columns are
// directly the lidar-frame tangent directions that the covariance and degeneracy analysis report.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace adit {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// T0 * Exp(xi) as defined above.
Eigen::Isometry3d applyIncrement(const Eigen::Isometry3d& T0, const Vector6d& xi);

// The xi with applyIncrement(T0, xi) == T (rotation angle below pi).
Vector6d incrementBetween(const Eigen::Isometry3d& T0, const Eigen::Isometry3d& T);

// Scales a relative motion by s in the tangent space (constant-velocity extrapolation over a different gap).
Eigen::Isometry3d scaleMotion(const Eigen::Isometry3d& delta, double s);

// True when a correspondence round moved the pose by less than 1 mm and 0.01 degree: recomputing the
// correspondences again would find the same ones, so further rounds are wasted time.
bool hasConverged(const Eigen::Isometry3d& before, const Eigen::Isometry3d& after);

// True when every entry of the pose is finite.
bool isFinitePose(const Eigen::Isometry3d& T);

}  // namespace adit
