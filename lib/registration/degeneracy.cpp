#include "registration/degeneracy.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>

namespace adit {
namespace {

// Eigen-analysis of one symmetric 3x3 block; flags directions whose eigenvalue is below ratio * largest.
void analyzeBlock(const Eigen::Matrix3d& block, double ratio, Eigen::Vector3d& values, Eigen::Matrix3d& vectors,
                  std::array<bool, 3>& degenerate) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (block + block.transpose()));
  values = eig.eigenvalues().cwiseMax(0.0);  // ascending
  vectors = eig.eigenvectors();
  const double largest = values[2];
  for (int i = 0; i < 3; ++i) degenerate[i] = !(largest > 0.0) || values[i] < ratio * largest;
}

}  // namespace

DegeneracyReport analyzeDegeneracy(const Matrix6d& information, double translation_ratio, double rotation_ratio) {
  DegeneracyReport r;
  if (!information.allFinite()) {
    r.translation_degenerate = r.rotation_degenerate = {{true, true, true}};
    r.flags = PoseEstimate::kDegenerateTranslation | PoseEstimate::kDegenerateRotation;
    return r;
  }
  analyzeBlock(information.topLeftCorner<3, 3>(), translation_ratio, r.translation_eigenvalues,
               r.translation_directions, r.translation_degenerate);
  analyzeBlock(information.bottomRightCorner<3, 3>(), rotation_ratio, r.rotation_eigenvalues,
               r.rotation_directions, r.rotation_degenerate);
  const auto any = [](const std::array<bool, 3>& a) { return a[0] || a[1] || a[2]; };
  if (any(r.translation_degenerate)) r.flags |= PoseEstimate::kDegenerateTranslation;
  if (any(r.rotation_degenerate)) r.flags |= PoseEstimate::kDegenerateRotation;
  return r;
}

Matrix6d covarianceFrom(const Matrix6d& information, const DegeneracyReport& report,
                        double prior_sigma_translation_m, double prior_sigma_rotation_rad) {
  const double prior_t = 1.0 / (prior_sigma_translation_m * prior_sigma_translation_m);
  const double prior_r = 1.0 / (prior_sigma_rotation_rad * prior_sigma_rotation_rad);
  Matrix6d info = information.allFinite() ? information : Matrix6d::Zero();
  info = 0.5 * (info + info.transpose()).eval();
  // Replace the information along each degenerate direction by the prior's: what was measured there is too
  // weak (or, with edges on curved walls, not trustworthy) to report.
  for (int i = 0; i < 3; ++i) {
    if (report.translation_degenerate[i]) {
      const Eigen::Vector3d v = report.translation_directions.col(i);
      const double measured = v.dot(info.topLeftCorner<3, 3>() * v);
      info.topLeftCorner<3, 3>() += (prior_t - measured) * v * v.transpose();
    }
    if (report.rotation_degenerate[i]) {
      const Eigen::Vector3d v = report.rotation_directions.col(i);
      const double measured = v.dot(info.bottomRightCorner<3, 3>() * v);
      info.bottomRightCorner<3, 3>() += (prior_r - measured) * v * v.transpose();
    }
  }
  // A floor of the prior information on the diagonal's scale keeps the inverse defined even when the
  // measurements constrain nothing at all (empty sweep); it is negligible next to real measurements.
  for (int i = 0; i < 3; ++i) info(i, i) += 1e-6 * prior_t;
  for (int i = 3; i < 6; ++i) info(i, i) += 1e-6 * prior_r;
  Matrix6d cov = info.ldlt().solve(Matrix6d::Identity());
  return 0.5 * (cov + cov.transpose());
}

}  // namespace adit
