// The loop closer refuses, before any ICP, the candidates whose every possible fit the odometry gate would refuse
// (loop_job.cpp, gateRefusesEveryFit): loopChi2LowerBound must never exceed the chi2 that judge() computes for a
// fit within the reach, full or partial (free along an axis the graph crosses by at most the offset), whatever
// the fit's rotation, including rotations that turn the free axis towards the residual.
#include "loop/loop_closer.hpp"
#include "loop/odometry_chain.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace adit {
namespace {

Eigen::Vector3d unitVector(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector3d v(n(rng), n(rng), n(rng));
  return v.normalized();
}

Eigen::Matrix3d rotation(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// A random covariance of a chain: translation sigmas 0.05-10 m, rotation 0.001-0.1 rad, correlated.
Matrix6d randomChainCovariance(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) A(i, j) = (u(rng) - 0.5) * 0.3;
  Eigen::Matrix<double, 6, 1> sigma;
  for (int i = 0; i < 3; ++i) sigma[i] = 0.05 * std::pow(200.0, u(rng));
  for (int i = 3; i < 6; ++i) sigma[i] = 0.001 * std::pow(100.0, u(rng));
  const Matrix6d S = sigma.asDiagonal() * (Matrix6d::Identity() + A) * sigma.asDiagonal();
  return S * S.transpose() / 2.0 + 1e-12 * Matrix6d::Identity();
}

TEST(OdometryGate, LowerBoundNeverExceedsTheChi2OfAFitWithinReach) {
  std::mt19937 rng(16);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  LoopCloserConfig config;
  const double offset = config.partial_loop_max_axis_offset;
  const Matrix6d loop_covariance = loopMeasurementCovariance(config);
  int bounded = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Matrix6d chain = randomChainCovariance(rng);
    Eigen::Isometry3d T_graph = Eigen::Isometry3d::Identity();
    T_graph.linear() = rotation(unitVector(rng), M_PI * u(rng));
    T_graph.translation() = unitVector(rng) * 200.0 * u(rng);
    const double reach = 40.0 * u(rng);
    const double bound = loopChi2LowerBound(T_graph.translation().norm(), reach, offset, chain, loop_covariance);
    ASSERT_GE(bound, 0.0);
    if (bound > 0.0) ++bounded;

    // A full fit anywhere within the reach, with any rotation.
    Eigen::Isometry3d Z = Eigen::Isometry3d::Identity();
    Z.translation() = unitVector(rng) * reach * u(rng);
    Z.linear() = rotation(unitVector(rng), M_PI * u(rng));
    ASSERT_LE(bound, loopChi2(Z, T_graph, chain, loop_covariance) * (1.0 + 1e-9)) << trial;

    // A partial fit: a free axis the graph crosses by at most the offset (as judge() requires), the fit's
    // translation replaced along it by the graph's, the covariance inflated along it.
    const Eigen::Vector3d t = T_graph.translation();
    Eigen::Vector3d axis = unitVector(rng);
    if (t.norm() > 1e-9) {  // tilt the axis towards the graph's direction just enough to meet the offset
      const Eigen::Vector3d along = t.normalized();
      const Eigen::Vector3d across = (axis - along * along.dot(axis)).normalized();
      const double max_sin = std::min(1.0, offset / t.norm());
      const double s = max_sin * (2.0 * u(rng) - 1.0);
      axis = across * std::sqrt(1.0 - s * s) + along * s;
    }
    // Half of the fits rotated adversarially: by up to 1 rad about the axis that turns the free axis towards
    // the translation residual, the one way the inflated covariance could hide the residual.
    Eigen::Isometry3d P = Z;
    if (trial % 2 == 0) {
      const Eigen::Vector3d w = Z.translation() - t;
      const Eigen::Vector3d turn = axis.cross(w);
      if (turn.norm() > 1e-9) P.linear() = rotation(turn, -u(rng)) * T_graph.linear();  // R_G R_P^T turns axis to w
    }
    P.translation() += axis * (axis.dot(t) - axis.dot(P.translation()));
    const Matrix6d partial = partialLoopCovariance(config, P.linear().transpose() * axis);
    ASSERT_LE(bound, loopChi2(P, T_graph, chain, partial) * (1.0 + 1e-9)) << trial;
  }
  EXPECT_GT(bounded, 5000);  // the bound is not trivially zero
}

// Far by the graph, close by the fit: a candidate 100 m away whose fits can reach 30 m is refused at the
// default gate when the chain's uncertainty is a few metres, and not when it is tens of metres.
TEST(OdometryGate, SeparatesOnlyWhatTheChainCannotExplain) {
  LoopCloserConfig config;
  const Matrix6d loop_covariance = loopMeasurementCovariance(config);
  Matrix6d chain = Matrix6d::Zero();
  chain.diagonal() << 9, 9, 1, 1e-4, 1e-4, 1e-3;  // 3 m, 3 m, 1 m; 0.6, 0.6, 1.8 deg
  EXPECT_GT(loopChi2LowerBound(100.0, 30.0, config.partial_loop_max_axis_offset, chain, loop_covariance),
            config.max_odometry_chi2);
  chain.diagonal() << 900, 900, 100, 1e-2, 1e-2, 1e-1;
  EXPECT_LT(loopChi2LowerBound(100.0, 30.0, config.partial_loop_max_axis_offset, chain, loop_covariance),
            config.max_odometry_chi2);
  EXPECT_EQ(loopChi2LowerBound(25.0, 30.0, 0.0, chain, loop_covariance), 0.0);  // within reach: no bound
  EXPECT_EQ(loopChi2LowerBound(8.0, 0.0, 10.0, chain, loop_covariance), 0.0);   // within the partial offset
}

}  // namespace
}  // namespace adit
