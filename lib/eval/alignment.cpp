#include "eval/alignment.hpp"

#include <Eigen/SVD>

#include <limits>
#include <stdexcept>

namespace adit::eval {

AlignMode parseAlignMode(const std::string& name) {
  if (name == "none") return AlignMode::kNone;
  if (name == "se3") return AlignMode::kSE3;
  if (name == "sim3") return AlignMode::kSim3;
  throw std::invalid_argument("unknown alignment '" + name + "' (use se3, sim3 or none)");
}

std::string toString(AlignMode mode) {
  switch (mode) {
    case AlignMode::kNone: return "none";
    case AlignMode::kSE3: return "se3";
    case AlignMode::kSim3: return "sim3";
  }
  return "none";
}

Similarity umeyama(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y, bool with_scale) {
  Similarity out;
  const std::size_t n = std::min(x.size(), y.size());
  if (n == 0) {
    out.degenerate = true;
    return out;
  }
  Eigen::Vector3d mean_x = Eigen::Vector3d::Zero(), mean_y = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mean_x += x[i];
    mean_y += y[i];
  }
  mean_x /= static_cast<double>(n);
  mean_y /= static_cast<double>(n);

  double sigma_x = 0.0;  // variance of x, eq. 36
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();  // eq. 38
  for (std::size_t i = 0; i < n; ++i) {
    sigma_x += (x[i] - mean_x).squaredNorm();
    cov += (y[i] - mean_y) * (x[i] - mean_x).transpose();
  }
  sigma_x /= static_cast<double>(n);
  cov /= static_cast<double>(n);

  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  const double eps = std::numeric_limits<double>::epsilon();
  const int rank = (d[0] > eps) + (d[1] > eps) + (d[2] > eps);
  if (rank < 2) {
    out.degenerate = true;
    out.translation = mean_y - mean_x;
    return out;
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();  // eq. 43: keep a right-handed rotation
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  out.rotation = svd.matrixU() * S * svd.matrixV().transpose();  // eq. 40
  out.scale = (with_scale && sigma_x > 0.0) ? (d.asDiagonal() * S).trace() / sigma_x : 1.0;  // eq. 42
  out.translation = mean_y - out.scale * out.rotation * mean_x;  // eq. 41
  return out;
}

Similarity solveAlignment(const Trajectory& gt, const Trajectory& est, AlignMode mode) {
  if (mode == AlignMode::kNone) return Similarity{};
  std::vector<Eigen::Vector3d> x, y;
  for (std::size_t i = 0; i < std::min(gt.size(), est.size()); ++i) {
    x.push_back(est[i].pose.translation());
    y.push_back(gt[i].pose.translation());
  }
  return umeyama(x, y, mode == AlignMode::kSim3);
}

Trajectory applyAlignment(const Trajectory& est, const Similarity& s) {
  Trajectory out = est;
  for (StampedPose& p : out) {
    p.pose.translation() = s.rotation * (s.scale * p.pose.translation()) + s.translation;
    p.pose.linear() = s.rotation * p.pose.linear();
  }
  return out;
}

}  // namespace adit::eval
