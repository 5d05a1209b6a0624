#include "loop/point_to_plane_icp.hpp"

#include "core/geometry.hpp"
#include "registration/jacobians.hpp"
#include "registration/kdtree.hpp"
#include "registration/robust_loss.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>

namespace adit {

struct PlaneTarget::Impl {
  KdTree3 planar;  // planar target points (the registration core's KD-tree)
  std::vector<Eigen::Vector3d> normals;
};

PlaneTarget::PlaneTarget(const std::vector<Eigen::Vector3f>& points, const IcpConfig& config)
    : impl_(std::make_unique<Impl>()) {
  std::vector<Eigen::Vector3d> finite;
  finite.reserve(points.size());
  for (const auto& p : points)
    if (p.allFinite()) finite.push_back(p.cast<double>());
  const int k = std::max(3, config.normal_neighbors);
  if (static_cast<int>(finite.size()) < k) return;
  const KdTree3 all(finite);
  std::vector<Eigen::Vector3d> planar;
  std::vector<int> idx;  // reused: no allocation per point
  for (const Eigen::Vector3d& p : finite) {
    all.nearestK(p, k, std::numeric_limits<double>::infinity(), idx);
    if (static_cast<int>(idx.size()) < k) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int i : idx) mean += all.point(i);
    mean /= k;
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (int i : idx) {
      const Eigen::Vector3d d = all.point(i) - mean;
      cov += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    const double total = eig.eigenvalues().sum();
    if (total <= 0.0 || eig.eigenvalues()[0] / total > config.max_surface_variation) continue;
    planar.push_back(p);
    impl_->normals.push_back(eig.eigenvectors().col(0));
  }
  impl_->planar = KdTree3(std::move(planar));
}

PlaneTarget::~PlaneTarget() = default;

int PlaneTarget::planarPoints() const { return static_cast<int>(impl_->planar.size()); }

bool PlaneTarget::nearest(const Eigen::Vector3d& query, double max_distance, Eigen::Vector3d& point,
                          Eigen::Vector3d& normal, NearestMemo& memo) const {
  const int i = impl_->planar.nearest(query, max_distance * max_distance, memo);
  if (i < 0) return false;
  point = impl_->planar.point(i);
  normal = impl_->normals[static_cast<std::size_t>(i)];
  return true;
}

namespace {

struct Linearisation {
  Matrix6d H = Matrix6d::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  Matrix6d H_inliers = Matrix6d::Zero();
  int correspondences = 0;
  int inliers = 0;
  double inlier_sq_sum = 0.0;
};

// Residual r = n . (T s - q); left perturbation T <- Exp(d) T gives dr/d(t, w) = [n, (T s) x n].
// memos[i]: source point i's nearest-point search, kept across the iterations (the same matches, fewer
// searches: late iterations move the points by millimetres).
Linearisation linearise(const PlaneTarget& target, const std::vector<Eigen::Vector3d>& source,
                        std::vector<NearestMemo>& memos, const Eigen::Isometry3d& T, double max_distance,
                        double inlier_residual) {
  Linearisation lin;
  // Huber at the inlier scale: far matches pull, but not quadratically.
  const RobustKernel huber{RobustLoss::kHuber, inlier_residual};
  Eigen::Vector3d q, n;
  for (std::size_t i = 0; i < source.size(); ++i) {
    const Eigen::Vector3d p = T * source[i];
    if (!target.nearest(p, max_distance, q, n, memos[i])) continue;
    const double r = n.dot(p - q);
    const Eigen::Matrix<double, 6, 1> J = planeRowLeft(n, p).transpose();
    const double w = huber.weight(r * r);
    lin.H.noalias() += (w * J) * J.transpose();
    lin.g.noalias() += (w * r) * J;
    ++lin.correspondences;
    if (std::abs(r) <= inlier_residual) {
      lin.H_inliers.noalias() += J * J.transpose();
      lin.inlier_sq_sum += r * r;
      ++lin.inliers;
    }
  }
  return lin;
}

// Gauss-Newton at one correspondence gate; returns true when the update became small.
bool runPhase(const PlaneTarget& target, const std::vector<Eigen::Vector3d>& source, std::vector<NearestMemo>& memos,
              double gate, const IcpConfig& config, Eigen::Isometry3d& T, int& iterations) {
  for (int it = 0; it < config.max_iterations; ++it) {
    const Linearisation lin = linearise(target, source, memos, T, gate, config.inlier_residual);
    ++iterations;
    if (lin.correspondences < 6) return false;
    const Eigen::Matrix<double, 6, 1> delta = -(lin.H + 1e-9 * Matrix6d::Identity()).ldlt().solve(lin.g);
    if (!delta.allFinite()) return false;
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.linear() = expRotation(delta.tail<3>());
    step.translation() = delta.head<3>();
    T = step * T;
    if (delta.head<3>().norm() < config.converged_translation && delta.tail<3>().norm() < config.converged_rotation)
      return true;
  }
  return false;
}

}  // namespace

IcpResult alignPointToPlane(const PlaneTarget& target, const std::vector<Eigen::Vector3f>& source,
                            const Eigen::Isometry3d& initial_T_target_source, const IcpConfig& config) {
  IcpResult result;
  result.T_target_source = initial_T_target_source;
  std::vector<Eigen::Vector3d> src;
  src.reserve(source.size());
  for (const auto& p : source)
    if (p.allFinite()) src.push_back(p.cast<double>());
  if (src.size() < 6 || target.planarPoints() < 6 || !initial_T_target_source.matrix().allFinite()) return result;

  Eigen::Isometry3d T = initial_T_target_source;
  std::vector<NearestMemo> memos(src.size());
  runPhase(target, src, memos, config.coarse_correspondence_distance, config, T, result.iterations);
  result.converged = runPhase(target, src, memos, config.fine_correspondence_distance, config, T, result.iterations);
  result.T_target_source = T;

  const Linearisation lin =
      linearise(target, src, memos, T, config.fine_correspondence_distance, config.inlier_residual);
  result.correspondences = lin.correspondences;
  result.inlier_ratio = static_cast<double>(lin.inliers) / static_cast<double>(src.size());
  result.rms = lin.inliers > 0 ? std::sqrt(lin.inlier_sq_sum / lin.inliers) : 0.0;
  result.hessian = lin.H_inliers;
  // Below ~1 cm the residual is the surfaces' own roughness, not the fit's quality.
  result.observability = analyseFit(lin.H_inliers, std::max(result.rms, 0.01));
  return result;
}

}  // namespace adit
