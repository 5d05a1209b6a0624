// Umeyama alignment: exact recovery, optimality on noisy data, proper rotations only, evo's apply order.
#include "eval/alignment.hpp"
#include "fixtures.hpp"

#include <gtest/gtest.h>

#include <random>

namespace adit::eval {
namespace {

double sumSquares(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y, const Similarity& s) {
  double sum = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) sum += (s.scale * s.rotation * x[i] + s.translation - y[i]).squaredNorm();
  return sum;
}

std::vector<Eigen::Vector3d> randomPoints(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i) out.emplace_back(u(rng), u(rng), 0.3 * u(rng));
  return out;
}

TEST(Umeyama, RecoversAKnownSimilarityExactly) {
  std::mt19937 rng(7);
  const std::vector<Eigen::Vector3d> x = randomPoints(50, rng);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(2.5, Eigen::Vector3d(-1, 0.5, 2).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(3, -7, 0.5);
  std::vector<Eigen::Vector3d> y;
  for (const auto& p : x) y.push_back(1.7 * R * p + t);
  const Similarity s = umeyama(x, y, true);
  EXPECT_FALSE(s.degenerate);
  EXPECT_NEAR(s.scale, 1.7, 1e-12);
  EXPECT_NEAR((s.rotation - R).norm(), 0.0, 1e-12);
  EXPECT_NEAR((s.translation - t).norm(), 0.0, 1e-11);
  const Similarity rigid = umeyama(x, y, false);
  EXPECT_DOUBLE_EQ(rigid.scale, 1.0);
  EXPECT_NEAR((rigid.rotation - R).norm(), 0.0, 1e-12);  // rotation does not depend on scale
}

TEST(Umeyama, IsALeastSquaresMinimumOnNoisyData) {
  // Independent of the closed form: no small perturbation of the result lowers the squared error.
  std::mt19937 rng(11);
  const std::vector<Eigen::Vector3d> x = randomPoints(200, rng);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::normal_distribution<double> noise(0.0, 0.2);
  std::vector<Eigen::Vector3d> y;
  for (const auto& p : x) y.push_back(R * p + Eigen::Vector3d(1, 2, 3) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  for (bool with_scale : {false, true}) {
    const Similarity best = umeyama(x, y, with_scale);
    const double f0 = sumSquares(x, y, best);
    for (int axis = 0; axis < 3; ++axis)
      for (double h : {-1e-3, 1e-3}) {
        Similarity s = best;
        s.rotation = Eigen::AngleAxisd(h, Eigen::Vector3d::Unit(axis)).toRotationMatrix() * best.rotation;
        EXPECT_GT(sumSquares(x, y, s), f0);
        s = best;
        s.translation[axis] += h;
        EXPECT_GT(sumSquares(x, y, s), f0);
        if (with_scale) {
          s = best;
          s.scale += h;
          EXPECT_GT(sumSquares(x, y, s), f0);
        }
      }
  }
}

TEST(Umeyama, NeverReturnsAReflection) {
  std::mt19937 rng(3);
  const std::vector<Eigen::Vector3d> x = randomPoints(30, rng);
  std::vector<Eigen::Vector3d> y;
  for (const auto& p : x) y.emplace_back(p.x(), p.y(), -p.z());  // mirror image
  const Similarity s = umeyama(x, y, false);
  EXPECT_NEAR(s.rotation.determinant(), 1.0, 1e-12);
  EXPECT_NEAR((s.rotation.transpose() * s.rotation - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
}

TEST(Umeyama, DegenerateInputIsFlaggedNotFatal) {
  EXPECT_TRUE(umeyama({}, {}, true).degenerate);
  const std::vector<Eigen::Vector3d> x = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  const std::vector<Eigen::Vector3d> y = {{0, 1, 0}, {1, 1, 0}, {2, 1, 0}};
  const Similarity s = umeyama(x, y, true);
  EXPECT_TRUE(s.degenerate);
  EXPECT_NEAR((s.translation - Eigen::Vector3d(0, 1, 0)).norm(), 0.0, 1e-12);
}

TEST(Alignment, AppliedLikeEvoScaleThenRigid) {
  Trajectory est = {{0, test::poseAt(Eigen::Vector3d(1, 0, 0), 0.3)}};
  Similarity s;
  s.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s.translation = Eigen::Vector3d(0, 0, 5);
  s.scale = 2.0;
  const Trajectory out = applyAlignment(est, s);
  EXPECT_NEAR((out[0].pose.translation() - Eigen::Vector3d(0, 2, 5)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(out[0].pose.linear()).angle(), M_PI / 2 + 0.3, 1e-12);
  EXPECT_EQ(parseAlignMode("sim3"), AlignMode::kSim3);
  EXPECT_THROW(parseAlignMode("affine"), std::invalid_argument);
}

}  // namespace
}  // namespace adit::eval
