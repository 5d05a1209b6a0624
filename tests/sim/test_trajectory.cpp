// B-spline ground truth: analytic derivatives equal numerical ones; paths are continuous.
#include "sim/bspline_trajectory.hpp"
#include "sim/path.hpp"
#include "sim/rng.hpp"

#include <gtest/gtest.h>

namespace adit::sim {
namespace {

BSplineTrajectory randomTrajectory(std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Eigen::Isometry3d> controls;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  for (int k = 0; k < 60; ++k) {
    p += Eigen::Vector3d(0.03, 0.01 * rng.normal(), 0.005 * rng.normal());
    R = R * so3Exp(Eigen::Vector3d(0.01 * rng.normal(), 0.01 * rng.normal(), 0.02 * rng.normal()));
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R;
    T.translation() = p;
    controls.push_back(T);
  }
  return BSplineTrajectory(0.0, 0.02, controls);
}

TEST(BSplineTrajectory, AnalyticDerivativesMatchFiniteDifferences) {
  const BSplineTrajectory traj = randomTrajectory(5);
  const double h = 1e-5;
  for (double t = 0.013; t < traj.endTime() - 0.01; t += 0.0377) {
    const TrajectoryState s = traj.state(t);
    const Eigen::Isometry3d a = traj.pose(t - h), b = traj.pose(t + h), c = traj.pose(t);
    EXPECT_LT((s.pose.matrix() - c.matrix()).norm(), 1e-12);
    const Eigen::Vector3d v_num = (b.translation() - a.translation()) / (2 * h);
    const Eigen::Vector3d a_num = (b.translation() - 2 * c.translation() + a.translation()) / (h * h);
    const Eigen::Vector3d w_num = so3Log(a.linear().transpose() * b.linear()) / (2 * h);
    EXPECT_LT((s.velocity - v_num).norm(), 1e-6 * (1 + v_num.norm())) << t;
    EXPECT_LT((s.acceleration - a_num).norm(), 2e-3 * (1 + a_num.norm())) << t;
    EXPECT_LT((s.angular_velocity - w_num).norm(), 1e-6 * (1 + w_num.norm())) << t;
  }
}

TEST(BSplineTrajectory, ContinuousAcrossKnots) {
  const BSplineTrajectory traj = randomTrajectory(9);
  for (int k = 1; k < 50; ++k) {
    const double t = k * 0.02;
    const TrajectoryState l = traj.state(t - 1e-9), r = traj.state(t + 1e-9);
    EXPECT_LT((l.pose.translation() - r.pose.translation()).norm(), 1e-8);  // 2e-9 s apart at ~1.5 m/s
    EXPECT_LT((l.velocity - r.velocity).norm(), 1e-6);
    EXPECT_LT((l.acceleration - r.acceleration).norm(), 1e-4);  // C2: acceleration continuous too
    EXPECT_LT((l.angular_velocity - r.angular_velocity).norm(), 1e-6);
  }
}

TEST(BSplineTrajectory, ConstantControlsGiveRest) {
  std::vector<Eigen::Isometry3d> controls(6, Eigen::Isometry3d(Eigen::Translation3d(1, 2, 3)));
  const BSplineTrajectory traj(0.0, 0.1, controls);
  const TrajectoryState s = traj.state(0.15);
  EXPECT_LT((s.pose.translation() - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
  EXPECT_LT(s.velocity.norm() + s.acceleration.norm() + s.angular_velocity.norm(), 1e-12);
}

TEST(Path2d, RoundedSquareIsContinuousWithExpectedLength) {
  const double side = 20.0, radius = 2.0;
  const Path2d path({{0, 0}, {side, 0}, {side, side}, {0, side}, {0, 0}, {side / 2, 0}}, radius);
  // Four rounded corners, each replacing 2r of straight line by a quarter circle.
  const double corners = 4, expected = 4 * side + side / 2 - corners * (2 * radius - M_PI / 2 * radius);
  EXPECT_NEAR(path.length(), expected, 1e-9);
  Path2d::Sample prev = path.at(0.0);
  for (double s = 0.01; s <= path.length(); s += 0.01) {
    const Path2d::Sample cur = path.at(s);
    EXPECT_NEAR((cur.position - prev.position).norm(), 0.01, 1e-6);  // arc length parameterisation
    EXPECT_LT(std::fabs(std::remainder(cur.heading - prev.heading, 2 * M_PI)), 0.01 / radius + 1e-9);
    prev = cur;
  }
  EXPECT_NEAR(path.at(path.length()).position.x(), side / 2, 1e-9);
}

}  // namespace
}  // namespace adit::sim
