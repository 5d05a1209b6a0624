// Analytic residuals and Jacobians of point-to-plane and point-to-line registration over a 6-DoF pose, in
// tangent order (translation, rotation). Two parameterisations:
// - right increment (pose_increment.hpp): T = T0 * Exp(xi), geometry given in T0's frame, Jacobians exact at
//   any xi (the SO(3) right Jacobian), what the per-sweep solver optimises;
// - left perturbation: T <- Exp(d) * T, Jacobians at d = 0 for a point already moved by T (ICP).
#pragma once

#include "core/geometry.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace adit {

using Matrix36d = Eigen::Matrix<double, 3, 6>;
using Row6d = Eigen::Matrix<double, 1, 6>;

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// The SO(3) right Jacobian: d Exp(phi + dphi) = Exp(phi) Exp(Jr(phi) dphi) to first order.
inline Eigen::Matrix3d rightJacobianSO3(const Eigen::Vector3d& phi) {
  const double theta2 = phi.squaredNorm();
  const Eigen::Matrix3d K = skew(phi);
  if (theta2 < 1e-10) return Eigen::Matrix3d::Identity() - 0.5 * K + (1.0 / 6.0) * K * K;
  const double theta = std::sqrt(theta2);
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(theta)) / theta2 * K +
         (theta - std::sin(theta)) / (theta2 * theta) * K * K;
}

// Rotation and right Jacobian at one value of xi = (rho, phi), shared by every residual of an iteration.
struct IncrementFrame {
  Eigen::Matrix3d R;   // Exp(phi)
  Eigen::Vector3d t;   // rho
  Eigen::Matrix3d Jr;  // right Jacobian at phi
  explicit IncrementFrame(const Eigen::Matrix<double, 6, 1>& xi)
      : R(expRotation(xi.tail<3>())), t(xi.head<3>()), Jr(rightJacobianSO3(xi.tail<3>())) {}
  Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return R * p + t; }
  // d(n . q)/d xi for q = R p + t: [n^T, (Jr^T (p x R^T n))^T].
  Row6d planeRow(const Eigen::Vector3d& n, const Eigen::Vector3d& p) const {
    Row6d J;
    J.head<3>() = n.transpose();
    J.tail<3>() = (Jr.transpose() * p.cross(R.transpose() * n)).transpose();
    return J;
  }
  // d((I - u u^T) q)/d xi: (I - u u^T) [I, -R [p]x Jr].
  Matrix36d lineJacobian(const Eigen::Vector3d& u, const Eigen::Vector3d& p) const {
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - u * u.transpose();
    Matrix36d J;
    J.leftCols<3>() = P;
    J.rightCols<3>().noalias() = -P * R * skew(p) * Jr;
    return J;
  }
};

// Point-to-plane: r = n . q + c, dr/dxi = n^T dq/dxi.
inline double planeResidual(const Eigen::Vector3d& n, double c, const Eigen::Vector3d& q) { return n.dot(q) + c; }

// Point-to-line (line through a with unit direction u): r = (I - u u^T)(q - a), 3 components, rank 2. Smooth
// at zero, unlike the scalar distance, which keeps Gauss-Newton well behaved on points already on their line.
inline Eigen::Vector3d lineResidual(const Eigen::Vector3d& a, const Eigen::Vector3d& u, const Eigen::Vector3d& q) {
  const Eigen::Vector3d d = q - a;
  return d - u * u.dot(d);
}

// Left perturbation at a moved point p = T s: dr/d(t, w) of r = n . (p - q) is [n, p x n].
inline Row6d planeRowLeft(const Eigen::Vector3d& n, const Eigen::Vector3d& p) {
  Row6d J;
  J.head<3>() = n.transpose();
  J.tail<3>() = p.cross(n).transpose();
  return J;
}

}  // namespace adit
