#include "loop/fit_observability.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <cmath>
#include <limits>

namespace adit {
namespace {

double ratio(double value, double largest) { return largest > 0.0 ? std::max(0.0, value) / largest : 0.0; }

}  // namespace

double FitObservability::weakestTranslationRatio() const {
  return ratio(translation_information[0], translation_information[2]);
}

double FitObservability::middleTranslationRatio() const {
  return ratio(translation_information[1], translation_information[2]);
}

FitObservability analyseFit(const Matrix6d& hessian, double residual_sigma_m) {
  FitObservability out;
  out.rotation_sigma_rad = std::numeric_limits<double>::infinity();
  if (!hessian.allFinite()) return out;
  const Eigen::Matrix3d Htt = hessian.topLeftCorner<3, 3>(), Hrr = hessian.bottomRightCorner<3, 3>();
  const Eigen::Matrix3d Htr = hessian.topRightCorner<3, 3>();
  // A wholly unconstrained direction makes a block singular; a ridge far below any measured information keeps
  // the other block's marginal finite there (its own weakness is still reported by its eigenvalues).
  const auto ridge = [](const Eigen::Matrix3d& m) {
    return (m + 1e-6 * std::max(m.trace(), 1e-12) * Eigen::Matrix3d::Identity()).eval();
  };
  const Eigen::FullPivLU<Eigen::Matrix3d> rr(ridge(Hrr)), tt(ridge(Htt));
  if (!rr.isInvertible() || !tt.isInvertible()) return out;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> trans(Htt - Htr * rr.solve(Htr.transpose()));
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rot(Hrr - Htr.transpose() * tt.solve(Htr));
  out.translation_information = trans.eigenvalues().cwiseMax(0.0);
  out.translation_directions = trans.eigenvectors();
  const double weakest_rotation = rot.eigenvalues()[0];
  if (weakest_rotation > 0.0) out.rotation_sigma_rad = residual_sigma_m / std::sqrt(weakest_rotation);
  return out;
}

}  // namespace adit
