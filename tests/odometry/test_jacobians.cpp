// The registration core's analytic Jacobians against central differences, at a non-zero increment (where the
// SO(3) right Jacobian matters), and its KD-tree against brute force.
#include "registration/jacobians.hpp"
#include "registration/kdtree.hpp"
#include "registration/pose_increment.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace adit {
namespace {

const Vector6d kXi = (Vector6d() << 0.3, -0.2, 0.1, 0.25, -0.4, 0.6).finished();

template <class F>
Eigen::MatrixXd numericJacobian(F f, const Vector6d& xi) {
  const Eigen::VectorXd f0 = f(xi);
  Eigen::MatrixXd J(f0.size(), 6);
  for (int i = 0; i < 6; ++i) {
    Vector6d d = Vector6d::Zero();
    d[i] = 1e-6;
    J.col(i) = (f(xi + d) - f(xi - d)) / 2e-6;
  }
  return J;
}

TEST(Jacobians, PlaneRowMatchesCentralDifferences) {
  const Eigen::Vector3d p(2.0, -1.0, 0.5), n = Eigen::Vector3d(0.3, 0.5, -0.8).normalized();
  const double c = 0.7;
  const auto residual = [&](const Vector6d& xi) {
    Eigen::VectorXd r(1);
    r[0] = planeResidual(n, c, IncrementFrame(xi).apply(p));
    return r;
  };
  const Eigen::MatrixXd numeric = numericJacobian(residual, kXi);
  EXPECT_LT((IncrementFrame(kXi).planeRow(n, p) - numeric).cwiseAbs().maxCoeff(), 1e-7);
}

TEST(Jacobians, LineJacobianMatchesCentralDifferences) {
  const Eigen::Vector3d p(-1.5, 3.0, 1.0), a(0.2, 0.1, -0.3), u = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  const auto residual = [&](const Vector6d& xi) -> Eigen::VectorXd { return lineResidual(a, u, IncrementFrame(xi).apply(p)); };
  const Eigen::MatrixXd numeric = numericJacobian(residual, kXi);
  EXPECT_LT((IncrementFrame(kXi).lineJacobian(u, p) - numeric).cwiseAbs().maxCoeff(), 1e-7);
}

TEST(Jacobians, IncrementFrameIsApplyIncrement) {
  const Eigen::Vector3d p(1.0, 2.0, 3.0);
  // T0 * Exp(xi) maps p to T0 * (R p + t).
  EXPECT_LT((applyIncrement(Eigen::Isometry3d::Identity(), kXi) * p - IncrementFrame(kXi).apply(p)).norm(), 1e-12);
}

TEST(KdTree, NearestKMatchesBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  std::vector<Eigen::Vector3d> pts(2000);
  for (auto& p : pts) p = {u(rng), u(rng), u(rng)};
  const KdTree3 tree(pts);
  for (int q = 0; q < 200; ++q) {
    const Eigen::Vector3d x(u(rng), u(rng), u(rng));
    std::vector<int> order(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) order[i] = static_cast<int>(i);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return (pts[a] - x).squaredNorm() < (pts[b] - x).squaredNorm(); });
    std::vector<int> expected;
    for (int i : order)
      if (static_cast<int>(expected.size()) < 5 && (pts[i] - x).squaredNorm() < 1.0) expected.push_back(i);
    EXPECT_EQ(tree.nearestK(x, 5, 1.0), expected);
    EXPECT_EQ(tree.nearest(x, 1e9, order[0]), order[1]);  // the exclusion skips the nearest
  }
}

}  // namespace
}  // namespace adit
