// The gyro in scan-to-scan odometry (issue 16, bias at rest): its bias measured while the robot stands
// (odometry/gyro_bias.hpp), and its rotation weighed by the registration (registration/solver.hpp).
#include "core/geometry.hpp"
#include "odometry/gyro_bias.hpp"
#include "registration/solver.hpp"
#include "synthetic_world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace adit {
namespace {

Eigen::Isometry3d rollBy(double rad, const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(rad, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T.translation() = t;
  return T;
}

// Point-to-plane matches of points on the given surfaces (reference frame) seen from a sweep at T_ref_sweep.
struct Surface {
  Eigen::Vector3d point, normal;
};
Correspondences planeMatches(const std::vector<Surface>& surfaces, const Eigen::Isometry3d& T_ref_sweep) {
  Correspondences c;
  for (const Surface& s : surfaces) c.planes.push_back({T_ref_sweep.inverse() * s.point, s.normal, -s.normal.dot(s.point)});
  return c;
}

// Faces across a roadway (x = const, points spread over the cross-section): they pin the position along x,
// the pitch and the yaw, and leave the roll about x (with the cross-section's position) to anything else.
std::vector<Surface> crossFaces() {
  std::vector<Surface> out;
  for (const double x : {-8.0, -3.0, 4.0, 9.0})
    for (int j = -5; j <= 5; ++j)
      for (int k = -5; k <= 5; ++k) out.push_back({{x, 0.4 * j, 0.3 * k}, {x < 0 ? 1.0 : -1.0, 0.0, 0.0}});
  return out;
}

// A 6 x 4 x 3 m room: its six faces pin every direction.
std::vector<Surface> boxRoom() {
  std::vector<Surface> out;
  for (int i = -5; i <= 5; ++i)
    for (int j = -5; j <= 5; ++j) {
      const double u = 0.18 * i, v = 0.18 * j;
      out.push_back({{3.0, 2 * u, 1.5 * v}, {-1, 0, 0}});
      out.push_back({{-3.0, 2 * u, 1.5 * v}, {1, 0, 0}});
      out.push_back({{3 * u, 2.0, 1.5 * v}, {0, -1, 0}});
      out.push_back({{3 * u, -2.0, 1.5 * v}, {0, 1, 0}});
      out.push_back({{3 * u, 2 * v, 1.5}, {0, 0, -1}});
      out.push_back({{3 * u, 2 * v, -1.5}, {0, 0, 1}});
    }
  return out;
}

double rollOf(const Eigen::Isometry3d& T) {
  const Eigen::AngleAxisd aa(T.linear());
  return (aa.angle() * aa.axis()).x();
}

RegistrationConfig plainConfig() {
  RegistrationConfig c;
  c.degeneracy_prior = false;  // the motion model out of the way: only the gyro may hold the roll
  c.max_solver_iterations = 20;
  return c;
}

TEST(GyroRotationPrior, HoldsTheRollThePointsLeaveFree) {
  const Eigen::Isometry3d truth = rollBy(0.02, {0.3, 0.0, 0.0});
  const Correspondences m = planeMatches(crossFaces(), truth);
  const RegistrationResult without = registerStep(m, Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity(), plainConfig());
  ASSERT_TRUE(without.ok);
  EXPECT_NEAR(rollOf(without.pose), 0.0, 1e-9);  // nothing sees the roll: the seed's stays
  EXPECT_NEAR(without.pose.translation().x(), 0.3, 1e-9);
  const RotationPrior gyro{truth.linear(), 1e-4};
  const RegistrationResult with = registerStep(m, Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity(), plainConfig(), &gyro);
  ASSERT_TRUE(with.ok);
  EXPECT_NEAR(rollOf(with.pose), 0.02, 1e-9);
  EXPECT_NEAR(with.pose.translation().x(), 0.3, 1e-9);
  EXPECT_LT(rotationAngle(truth.inverse() * with.pose), 1e-8);
}

TEST(GyroRotationPrior, IsWeighedAgainstThePoints) {
  const Eigen::Isometry3d truth = rollBy(0.01, {0.05, 0.0, 0.0});
  const Correspondences m = planeMatches(boxRoom(), truth);
  const Eigen::Matrix3d wrong = Eigen::Matrix3d::Identity();  // a gyro 0.01 rad off
  const RotationPrior loose{wrong, 1.0}, tight{wrong, 1e-7};
  const auto solve = [&](const RotationPrior& p) {
    return registerStep(m, Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity(), plainConfig(), &p);
  };
  EXPECT_NEAR(rollOf(solve(loose).pose), 0.01, 1e-4);  // the room pins the roll: a loose prior barely moves it
  EXPECT_NEAR(rollOf(solve(tight).pose), 0.0, 1e-4);   // a tight one wins
  // Between the two: exactly the weighted mean along the roll, a measure of the prior's weight.
  const RegistrationResult mid = solve({wrong, 1e-3});
  EXPECT_GT(rollOf(mid.pose), 0.0005);
  EXPECT_LT(rollOf(mid.pose), 0.0095);
}

// 200 Hz gyro of a robot: bias + white noise + the chassis rocking (an idling engine) + the rate it turns.
struct GyroStream {
  Eigen::Vector3d bias{0.003, -0.002, 0.001};
  double noise_density = 1.7e-4;  // rad/s/sqrt(Hz), the simulator's N100
  double rock_amplitude = 0.0026;  // rad (0.15 deg) at rock_hz
  double rock_hz = 1.3;
  std::mt19937 rng{7};

  std::vector<ImuSample> interval(std::int64_t t0, std::int64_t t1, const Eigen::Vector3d& turn_rate,
                                  const Eigen::Vector3d& accel) {
    std::normal_distribution<double> n(0.0, noise_density * std::sqrt(200.0));
    std::vector<ImuSample> out;
    for (std::int64_t t = t0 + 5000; t <= t1; t += 5000) {
      const double s = toSeconds(t), w = 2.0 * M_PI * rock_hz;
      ImuSample m;
      m.utime = t;
      m.gyro = bias + turn_rate + Eigen::Vector3d(rock_amplitude * w * std::cos(w * s), 0.7 * rock_amplitude * w * std::sin(1.3 * w * s), 0.0) +
               Eigen::Vector3d(n(rng), n(rng), n(rng));
      m.accel = accel + Eigen::Vector3d(0.0, 0.0, 9.81);
      out.push_back(m);
    }
    return out;
  }
};

// The lidar's step over a sweep interval: forward by `metres`.
Eigen::Isometry3d stepOf(double metres) { return test::poseFrom(metres, 0.0, 0.0, 0.0, 0.0, 0.0); }

TEST(GyroBias, MeasuredWhileTheRobotStandsOnAnIdlingChassis) {
  GyroStream gyro;
  GyroBiasEstimator estimator;
  for (int k = 0; k < 100; ++k) {  // 10 s still; the lidar sees ~1 cm of noise a sweep
    const std::int64_t t0 = k * 100000, t1 = t0 + 100000;
    estimator.observe(gyro.interval(t0, t1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()), t0, t1, stepOf(0.01), true);
  }
  ASSERT_TRUE(estimator.known());
  EXPECT_EQ(estimator.restPeriods(), 1);
  // The rocking's net rotation over the period / its length, plus the noise: a few 1e-4 rad/s.
  EXPECT_LT((estimator.bias() - gyro.bias).norm(), 4e-4) << estimator.bias().transpose();
  // Known to ~1e-4 rad/s after 10 s: a sweep's rotation widened by ~1e-5 rad.
  EXPECT_LT(estimator.biasSigma(), 2e-4);
  EXPECT_NEAR(estimator.rotationSigma(1e-4, 0.1), 1e-4, 2e-6);
}

// Two seconds still on a chassis rocking 0.15 deg: the mean rate errs by the net rotation between the
// period's ends over 2 s (up to ~2.6e-3 rad/s here); the slope fitted to the integrated angle does not, and
// the estimate says how well it knows the bias.
TEST(GyroBias, AShortStopOnARockingChassisIsFittedNotAveraged) {
  for (const double phase_s : {0.0, 0.2, 0.4, 0.6}) {
    GyroStream gyro;
    GyroBiasEstimator estimator;
    const std::int64_t start = toUtime(phase_s);
    for (int k = 0; k < 25; ++k) {  // 2.5 s still: 2 s trusted behind the 0.5 s guard
      const std::int64_t t0 = start + k * 100000, t1 = t0 + 100000;
      estimator.observe(gyro.interval(t0, t1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()), t0, t1, stepOf(0.01), true);
    }
    ASSERT_TRUE(estimator.known());
    const double error = (estimator.bias() - gyro.bias).norm();
    std::printf("phase %.1f s: bias error %.2e rad/s, sigma %.2e\n", phase_s, error, estimator.biasSigma());
    EXPECT_LT(error, 8e-4) << estimator.bias().transpose();
    EXPECT_LT(error, 3.0 * estimator.biasSigma() * std::sqrt(3.0));
    EXPECT_GT(estimator.biasSigma(), 1e-4);  // a short stop is not trusted like a long one
  }
}

TEST(GyroBias, UnknownUntilTheRobotStops) {
  GyroStream gyro;
  GyroBiasEstimator estimator;
  for (int k = 0; k < 100; ++k) {  // driving at 1.2 m/s from the start
    const std::int64_t t0 = k * 100000, t1 = t0 + 100000;
    estimator.observe(gyro.interval(t0, t1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()), t0, t1, stepOf(0.12), true);
  }
  EXPECT_FALSE(estimator.known());
  EXPECT_EQ(estimator.bias(), Eigen::Vector3d::Zero());
  // Unknown: the gyro's sigma is widened by the bias's own (5e-3 rad/s over 0.1 s).
  EXPECT_NEAR(estimator.rotationSigma(1e-4, 0.1), std::hypot(1e-4, 5e-4), 1e-12);
}

TEST(GyroBias, APullAwayThatTheLidarBarelySeesStaysOut) {
  GyroStream gyro;
  gyro.rock_amplitude = 0.0;
  GyroBiasEstimator estimator;
  double v = 0.0;
  for (int k = 0; k < 60; ++k) {
    const std::int64_t t0 = k * 100000, t1 = t0 + 100000;
    const bool moving = k >= 30;  // 3 s still, then 0.3 m/s^2 forward while pitching and turning
    const Eigen::Vector3d accel = moving ? Eigen::Vector3d(0.3, 0.0, 0.0) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d turn = moving ? Eigen::Vector3d(0.0, 0.01, 0.015) : Eigen::Vector3d::Zero();
    v += moving ? 0.03 : 0.0;  // the lidar's step stays under 5 cm for 1.6 s
    estimator.observe(gyro.interval(t0, t1, turn, accel), t0, t1, stepOf(v * 0.1), true);
  }
  ASSERT_TRUE(estimator.known());
  // Had the turning second entered, the bias would be ~5e-3 rad/s off.
  EXPECT_LT((estimator.bias() - gyro.bias).norm(), 4e-4) << estimator.bias().transpose();
}

TEST(GyroBias, ASlowTurnOnTheSpotIsNoBias) {
  GyroStream gyro;
  GyroBiasEstimator estimator;
  for (int k = 0; k < 100; ++k) {  // turning 3 deg/s on the spot: 0.3 deg a sweep, under the still angle
    const std::int64_t t0 = k * 100000, t1 = t0 + 100000;
    estimator.observe(gyro.interval(t0, t1, Eigen::Vector3d(0.0, 0.0, 0.05), Eigen::Vector3d::Zero()), t0, t1,
                      stepOf(0.0), true);
  }
  EXPECT_FALSE(estimator.known());
}

TEST(GyroBias, AFailedRegistrationEndsAStillPeriod) {
  GyroStream gyro;
  GyroBiasEstimator estimator;
  for (int k = 0; k < 100; ++k) {  // still, but every 8th registration fails: no period reaches 1 s + guard
    const std::int64_t t0 = k * 100000, t1 = t0 + 100000;
    estimator.observe(gyro.interval(t0, t1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()), t0, t1, stepOf(0.0),
                      k % 8 != 0);
  }
  EXPECT_FALSE(estimator.known());
}

}  // namespace
}  // namespace adit
