// Small SE(3) helpers for the loop closer, in the tangent order used across adit: (tx ty tz rx ry rz), with
// perturbations applied on the right (in the body frame): T_true = T * Exp(xi).
#pragma once

#include "core/types.hpp"

namespace adit {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// First-order difference a [-] b: translation and rotation vector of b^-1 * a (expressed in b's frame).
Vector6d boxMinus(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);

// Adjoint of T for right perturbations: T * Exp(xi) = Exp(adjoint(T) * xi) * T, tangent order (t, r).
Matrix6d adjoint(const Eigen::Isometry3d& T);

// T with its rotation part projected back onto a rotation (through a unit quaternion).
Eigen::Isometry3d orthonormal(const Eigen::Isometry3d& T);

// Symmetric, finite and positive definite (LLT succeeds)?
bool isValidCovariance(const Matrix6d& covariance);

// Squared Mahalanobis norm e^T S^-1 e; +infinity when S is not positive definite.
double mahalanobisSquared(const Vector6d& e, const Matrix6d& S);

}  // namespace adit
