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

// A query walked in steps of 0.1-20 mm (an ICP's late iterations) and sometimes jumped: the memo's answer is a
// fresh search's every time, across bounds that change (an ICP's coarse then fine gate), on points 100 m from
// the origin (float rounding); and most small steps are answered without a search.
TEST(KdTree, NearestMemoGivesTheSearchAnswer) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-5.0, 5.0), step(-0.02, 0.02), unit(0.0, 1.0);
  const Eigen::Vector3d far(100.0, -80.0, 3.0);
  std::vector<Eigen::Vector3d> pts(3000);
  for (auto& p : pts) p = far + Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng));
  // Exact duplicates and a point between two others at equal distances: ties must not be taken from the memo.
  pts.push_back(pts[10]);
  pts.push_back(pts[20]);
  const KdTree3 tree(pts);
  int answered = 0, steps = 0;
  for (int walk = 0; walk < 100; ++walk) {
    NearestMemo memo;
    Eigen::Vector3d x = walk % 10 == 0 ? pts[walk] : far + Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng));
    for (int s = 0; s < 40; ++s, ++steps) {
      const double bound_sq = s < 20 ? 1.5 * 1.5 : 0.5 * 0.5;
      const int expected = tree.nearest(x, bound_sq);
      const Eigen::Vector3f before = memo.at;
      ASSERT_EQ(tree.nearest(x, bound_sq, memo), expected) << "walk " << walk << " step " << s;
      if (memo.at == before && memo.index >= 0) ++answered;
      x += (unit(rng) < 0.05 ? 20.0 : unit(rng) < 0.5 ? 1.0 : 0.005) * Eigen::Vector3d(step(rng), step(rng), step(rng));
    }
  }
  EXPECT_GT(answered, steps / 3);
}

}  // namespace
}  // namespace adit
