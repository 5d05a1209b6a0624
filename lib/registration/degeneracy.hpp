// Degeneracy analysis of a registration problem from its information matrix (J^T J / sigma^2), after
// Zhang, Kaess, Singh 2016, "On degeneracy of optimization-based state estimation problems", but with
// relative thresholds: translation and rotation blocks are analysed separately (their units differ) and an
// eigen-direction is degenerate when its eigenvalue is below `min_eigenvalue_ratio` times the largest of its
// block. Relative thresholds do not depend on the number of points, the noise level or the scene size.
#pragma once

#include "core/types.hpp"

#include <array>

namespace adit {

struct DegeneracyReport {
  Eigen::Vector3d translation_eigenvalues = Eigen::Vector3d::Zero();  // ascending, 1/m^2
  Eigen::Vector3d rotation_eigenvalues = Eigen::Vector3d::Zero();     // ascending, 1/rad^2
  Eigen::Matrix3d translation_directions = Eigen::Matrix3d::Identity();  // columns match the eigenvalues
  Eigen::Matrix3d rotation_directions = Eigen::Matrix3d::Identity();
  std::array<bool, 3> translation_degenerate{{false, false, false}};
  std::array<bool, 3> rotation_degenerate{{false, false, false}};
  std::int32_t flags = 0;  // PoseEstimate::kDegenerateTranslation / kDegenerateRotation
};

// Separate ratios because rotation information grows with the square of the lever arm: in a long roadway
// yaw is observed by walls tens of metres away while roll only by the cross-section, a few metres, so a
// well-determined roll sits (w/L)^2 ~ 1/300 below yaw. Its ratio must be lower to flag only real loss.
DegeneracyReport analyzeDegeneracy(const Matrix6d& information, double translation_ratio, double rotation_ratio);

// Covariance of the estimate: the inverse of the measurement information, where every degenerate direction
// gets the motion model's information instead (1 / prior_sigma^2), so its variance is the prior's, never
// the near-infinite or meaningless value of an unobserved direction.
Matrix6d covarianceFrom(const Matrix6d& information, const DegeneracyReport& report,
                        double prior_sigma_translation_m, double prior_sigma_rotation_rad);

}  // namespace adit
