// Which directions a point-to-plane fit pins, from its Hessian (sum of J^T J over the inliers, tangent order
// (t, r)). Translations and rotations are judged apart, each with the other marginalised out (Schur
// complement): a relative test for translation (an eigenvalue far below the largest is a direction the scene
// does not constrain, such as the axis of a smooth straight roadway) and an absolute one for rotation, its
// standard deviation at the fit's residual. Scaling rotations by one lever arm instead (points "10 m away")
// counts the roll about a roadway's axis as free when its points are 2-3 m from the axis, though floor and
// walls pin it to a fraction of a degree.
#pragma once

#include "core/types.hpp"

namespace adit {

struct FitObservability {
  Eigen::Vector3d translation_information = Eigen::Vector3d::Zero();  // eigenvalues, ascending (per unit residual)
  Eigen::Matrix3d translation_directions = Eigen::Matrix3d::Identity();  // columns match the eigenvalues
  double rotation_sigma_rad = 0.0;  // standard deviation of the least constrained rotation (inf: unconstrained)

  // Smallest / largest and middle / largest translation eigenvalue: ~0 where a direction is unconstrained.
  double weakestTranslationRatio() const;
  double middleTranslationRatio() const;
  Eigen::Vector3d weakestTranslation() const { return translation_directions.col(0); }
};

// `residual_sigma_m`: the fit's point-to-plane residual (its inlier RMS), floored by the caller.
FitObservability analyseFit(const Matrix6d& hessian, double residual_sigma_m);

}  // namespace adit
