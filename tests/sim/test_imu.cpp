// IMU: readings consistent with the trajectory (integration reproduces ground truth), gravity at rest, noise
// statistics as configured.
#include "sim/imu_model.hpp"
#include "sim/simulator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace adit::sim {
namespace {

const Simulator& loopRun() {
  static const Simulator sim([] {
    SimConfig c;
    c.world = "roadway-loop";
    c.duration_s = 150.0;
    return c;
  }());
  return sim;
}

// Strapdown integration of noiseless samples (trapezoidal in rotation and velocity) from the true initial state
// over `seconds` reproduces the ground-truth pose: position error < 5 mm, attitude error < 0.005 deg over 5 s
// (observed: ~0.6 mm and ~0.001 deg, the trapezoidal rule's own error at 200 Hz).
// (Dead reckoning error grows like t^2 with any inconsistency: a wrong gravity sign or frame would give metres.)
void expectIntegrationMatchesTruth(const BSplineTrajectory& traj, double t0, double seconds) {
  ImuConfig config;
  config.noiseless = true;
  ImuSimulator imu(config, 1);
  const double h = 1.0 / config.rate_hz;
  const Eigen::Vector3d g(0, 0, -config.gravity);
  TrajectoryState s0 = traj.state(t0);
  Eigen::Matrix3d R = s0.pose.linear();
  Eigen::Vector3d p = s0.pose.translation(), v = s0.velocity;
  ImuSample prev = imu.sample(traj, t0, 0);
  const int steps = static_cast<int>(std::lround(seconds * config.rate_hz));
  for (int k = 1; k <= steps; ++k) {
    const ImuSample cur = imu.sample(traj, t0 + k * h, k);
    const Eigen::Vector3d a0 = R * prev.accel + g;
    const Eigen::Matrix3d R1 = R * so3Exp(0.5 * (prev.gyro + cur.gyro) * h);
    const Eigen::Vector3d a1 = R1 * cur.accel + g;
    p += v * h + h * h * (a0 / 3.0 + a1 / 6.0);
    v += 0.5 * (a0 + a1) * h;
    R = R1;
    prev = cur;
  }
  const Eigen::Isometry3d truth = traj.pose(t0 + seconds);
  const double angle = Eigen::AngleAxisd(truth.linear().transpose() * R).angle();
  std::printf("IMU dead reckoning over %.1f s from t=%.1f: position error %.2f mm, attitude error %.4f deg\n", seconds,
              t0, 1e3 * (p - truth.translation()).norm(), angle * 180.0 / M_PI);
  EXPECT_LT((p - truth.translation()).norm(), 0.005) << "t0=" << t0;
  EXPECT_LT(angle, 0.005 * M_PI / 180.0) << "t0=" << t0;
  // The motion was real: the robot moved metres.
  EXPECT_GT((truth.translation() - s0.pose.translation()).norm(), 3.0);
}

TEST(ImuConsistency, IntegratingNoiselessImuReproducesTruthWhileDriving) {
  expectIntegrationMatchesTruth(loopRun().trajectory(), 20.0, 5.0);
}

TEST(ImuConsistency, IntegratingNoiselessImuReproducesTruthThroughACorner) {
  const Simulator& sim = loopRun();
  // First corner of the loop: the middle of its 2 m radius arc, 153 m + pi/2 m from the start at x = 20.
  const double t_corner = sim.timeAtDistance(153.0 + M_PI / 2);
  ASSERT_LT(t_corner, 140.0);
  expectIntegrationMatchesTruth(sim.trajectory(), t_corner - 2.5, 5.0);
  // It was a 90 deg left turn.
  auto yaw = [&](double t) {
    const Eigen::Matrix3d R = sim.trajectory().pose(t).linear();
    return std::atan2(R(1, 0), R(0, 0));
  };
  const double yaw0 = yaw(t_corner - 8), yaw1 = yaw(t_corner + 8);
  EXPECT_NEAR(std::remainder(yaw1 - yaw0, 2 * M_PI), M_PI / 2, 0.1);
}

TEST(ImuAtRest, MeasuresGravityAndNoRotation) {
  const Simulator& sim = loopRun();
  ImuConfig config;
  config.noiseless = true;
  ImuSimulator imu(config, 1);
  for (double t = 0.1; t < 1.9; t += 0.3) {  // the robot stands still for 2 s
    const ImuSample s = imu.sample(sim.trajectory(), t, 0);
    EXPECT_LT(s.gyro.norm(), 1e-12);
    const Eigen::Vector3d up_body = sim.trajectory().pose(t).linear().transpose() * Eigen::Vector3d::UnitZ();
    EXPECT_LT((s.accel - config.gravity * up_body).norm(), 1e-9);  // specific force points up
  }
}

TEST(ImuNoise, WhiteNoiseAndBiasAsConfigured) {
  const Simulator& sim = loopRun();
  ImuConfig noisy;  // defaults
  ImuConfig exact = noisy;
  exact.noiseless = true;
  ImuSimulator a(noisy, 77), b(exact, 77);
  const int n = 4000;
  Eigen::Vector3d sum_g = Eigen::Vector3d::Zero(), sum2_g = Eigen::Vector3d::Zero(), sum_a = Eigen::Vector3d::Zero(),
                  sum2_a = Eigen::Vector3d::Zero();
  ImuTruth truth;
  Eigen::Vector3d first_bias = Eigen::Vector3d::Zero();
  for (int k = 0; k < n; ++k) {
    const double t = 10.0 + k / noisy.rate_hz;
    const ImuSample sa = a.sample(sim.trajectory(), t, k, &truth), sb = b.sample(sim.trajectory(), t, k);
    if (k == 0) first_bias = truth.gyro_bias;
    const Eigen::Vector3d eg = sa.gyro - sb.gyro - truth.gyro_bias, ea = sa.accel - sb.accel - truth.accel_bias;
    sum_g += eg;
    sum2_g += eg.cwiseAbs2();
    sum_a += ea;
    sum2_a += ea.cwiseAbs2();
  }
  const double sigma_g = noisy.gyro_noise * std::sqrt(noisy.rate_hz), sigma_a = noisy.accel_noise * std::sqrt(noisy.rate_hz);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(std::sqrt(sum2_g[k] / n), sigma_g, 0.06 * sigma_g);
    EXPECT_NEAR(std::sqrt(sum2_a[k] / n), sigma_a, 0.06 * sigma_a);
    EXPECT_NEAR(sum_g[k] / n, 0.0, 4 * sigma_g / std::sqrt(n));
  }
  // Turn-on bias is present and of the configured size; it walks but slowly (20 s of walk: ~1e-4 rad/s).
  EXPECT_GT(first_bias.norm(), 1e-4);
  EXPECT_LT(first_bias.norm(), 6 * noisy.gyro_bias_init);
  EXPECT_LT((truth.gyro_bias - first_bias).norm(), 10 * noisy.gyro_bias_walk * std::sqrt(20.0));
  EXPECT_GT((truth.gyro_bias - first_bias).norm(), 0.0);
}

}  // namespace
}  // namespace adit::sim
