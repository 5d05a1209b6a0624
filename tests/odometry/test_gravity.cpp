// Gravity from the accelerometer: the odometry's preintegration between sweeps (odometry/specific_force.hpp),
// the fit of gravity over a window of registered sweeps and the map's levelling (mapping/gravity.hpp). The IMU
// is synthesised from a known trajectory: f = R^T (a - g), 200 Hz, sweeps at 10 Hz.
#include "core/geometry.hpp"
#include "mapping/gravity.hpp"
#include "odometry/specific_force.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace adit {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr std::int64_t kImuUs = 5000, kSweepUs = 100000;

double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// A robot weaving, speeding up and slowing down, turning and rocking; its world is not levelled: gravity
// points 3 deg away from -z.
struct Trajectory {
  Eigen::Vector3d gravity = expRotation(Eigen::Vector3d(3 * kDeg, -1 * kDeg, 0)) * Eigen::Vector3d(0, 0, -9.80665);
  Eigen::Vector3d position(double t) const {
    return {1.2 * t + 0.8 * std::sin(0.4 * t), 0.05 * t * t + 0.5 * std::sin(0.9 * t), 0.1 * std::sin(0.3 * t)};
  }
  Eigen::Vector3d acceleration(double t) const {
    return {-0.128 * std::sin(0.4 * t), 0.1 - 0.405 * std::sin(0.9 * t), -0.009 * std::sin(0.3 * t)};
  }
  Eigen::Matrix3d rotation(double t) const {
    return expRotation(Eigen::Vector3d(0.02 * std::sin(1.3 * t), 0.015 * std::sin(0.7 * t), 0.2 * t));
  }
  Eigen::Isometry3d pose(double t) const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = rotation(t);
    T.translation() = position(t);
    return T;
  }
  ImuSample imu(std::int64_t utime, double accel_scale = 1.0) const {
    const double t = toSeconds(utime);
    ImuSample s;
    s.utime = utime;
    s.accel = accel_scale * rotation(t).transpose() * (acceleration(t) - gravity);
    return s;
  }
  std::vector<ImuSample> imuBetween(std::int64_t from, std::int64_t to, double accel_scale = 1.0) const {
    std::vector<ImuSample> out;
    for (std::int64_t u = from; u <= to; u += kImuUs) out.push_back(imu(u, accel_scale));
    return out;
  }
  // The sweep at utime's integral since the sweep before (R_curr_prev from the true rotations).
  SpecificForceIntegral integral(std::int64_t utime, double accel_scale = 1.0) const {
    const std::int64_t since = utime - kSweepUs;
    const Eigen::Matrix3d R_curr_prev = rotation(toSeconds(utime)).transpose() * rotation(toSeconds(since));
    return integrateSpecificForce(imuBetween(since - 2 * kImuUs, utime + 2 * kImuUs, accel_scale), since, utime,
                                  R_curr_prev, Eigen::Quaterniond::Identity(), 0.02);
  }
};

TEST(SpecificForce, IntegratesTheForceOnceAndTwiceInTheSweepsFrame) {
  // At rest, level: +9.81 up for 0.1 s.
  std::vector<ImuSample> still;
  for (std::int64_t u = 0; u <= kSweepUs; u += kImuUs) {
    still.emplace_back();
    still.back().utime = u;
    still.back().accel = Eigen::Vector3d(0, 0, 9.8);
  }
  const SpecificForceIntegral at_rest =
      integrateSpecificForce(still, 0, kSweepUs, Eigen::Matrix3d::Identity(), Eigen::Quaterniond::Identity(), 0.02);
  ASSERT_TRUE(at_rest.valid());
  EXPECT_NEAR((at_rest.velocity_change - Eigen::Vector3d(0, 0, 0.98)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((at_rest.displacement - Eigen::Vector3d(0, 0, 0.049)).norm(), 0.0, 1e-9);
  // A moving, turning robot: the integral matches the one of the exact force, in the frame at the end.
  const Trajectory traj;
  const std::int64_t utime = 3 * kSweepUs * 10;
  const SpecificForceIntegral moving = traj.integral(utime);
  ASSERT_TRUE(moving.valid());
  Eigen::Vector3d v = Eigen::Vector3d::Zero(), p = Eigen::Vector3d::Zero();
  const Eigen::Matrix3d R_end = traj.rotation(toSeconds(utime));
  for (int i = 0; i < 1000; ++i) {  // fine midpoint rule
    const double dt = 1e-4, t = toSeconds(utime - kSweepUs) + (i + 0.5) * dt;
    const Eigen::Vector3d f = R_end.transpose() * (traj.acceleration(t) - traj.gravity);
    p += v * dt + 0.5 * f * dt * dt;
    v += f * dt;
  }
  EXPECT_LT((moving.velocity_change - v).norm(), 2e-3);  // of ~1 m/s: the 200 Hz rectangles
  EXPECT_LT((moving.displacement - p).norm(), 2e-4);
}

TEST(SpecificForce, NoIntegralWhereTheSamplesDoNotCoverTheInterval) {
  const Trajectory traj;
  const std::int64_t since = 2000000, utime = since + kSweepUs;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Quaterniond none = Eigen::Quaterniond::Identity();
  std::vector<ImuSample> gap = traj.imuBetween(since, utime);
  gap.erase(gap.begin() + 5, gap.begin() + 12);  // 40 ms without a sample
  EXPECT_FALSE(integrateSpecificForce(gap, since, utime, I, none, 0.02).valid());
  EXPECT_FALSE(integrateSpecificForce(traj.imuBetween(since, utime - 30000), since, utime, I, none, 0.02).valid());
  std::vector<ImuSample> nan = traj.imuBetween(since, utime);
  nan[7].accel.x() = std::nan("");
  EXPECT_FALSE(integrateSpecificForce(nan, since, utime, I, none, 0.02).valid());
  EXPECT_FALSE(integrateSpecificForce({}, since, utime, I, none, 0.02).valid());
  EXPECT_TRUE(integrateSpecificForce(traj.imuBetween(since, utime), since, utime, I, none, 0.02).valid());
}

// Feeds the observer the trajectory's sweeps from t0 for `seconds`, positions with `noise_m` per axis; returns
// the worst angle between the gravity found and the truth, and how many sweeps found one.
struct Found {
  double worst_deg = 0.0;
  int count = 0;
};
Found observe(GravityObserver& observer, const Trajectory& traj, double t0, double seconds, double noise_m,
              double accel_scale = 1.0) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  Found out;
  for (std::int64_t u = toUtime(t0); u <= toUtime(t0 + seconds); u += kSweepUs) {
    Eigen::Isometry3d T = traj.pose(toSeconds(u));
    T.translation() += noise_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    const auto g = observer.add(u, T, traj.integral(u, accel_scale));
    if (!g) continue;
    ++out.count;
    out.worst_deg = std::max(out.worst_deg, angleBetween(*g, traj.gravity) / kDeg);
  }
  return out;
}

TEST(GravityObserver, FindsGravityWhileTheRobotWeavesAcceleratesAndTurns) {
  // The robot's acceleration (up to 0.5 m/s^2: 3 deg if it were taken for gravity) is carried by the fit.
  GravityObserver exact;
  const Found e = observe(exact, Trajectory{}, 1.0, 40.0, 0.0);
  EXPECT_EQ(e.count, 301);  // from the first whole 10 s window on
  EXPECT_LT(e.worst_deg, 0.01);
  // Registered positions scattered by 5 mm per axis: ~0.01 deg.
  GravityObserver noisy;
  const Found n = observe(noisy, Trajectory{}, 1.0, 40.0, 0.005);
  EXPECT_LT(n.worst_deg, 0.05);
  std::printf("gravity found: exact %.4f deg, 5 mm position noise %.4f deg (worst)\n", e.worst_deg, n.worst_deg);
}

TEST(GravityObserver, TrustsNoAccelerometerOutOfScaleAndStartsAgainAfterAGap) {
  GravityObserver observer;
  const Found scaled = observe(observer, Trajectory{}, 1.0, 20.0, 0.0, 1.2);  // 11.8 m/s^2
  EXPECT_EQ(scaled.count, 0);
  EXPECT_GT(observer.rejected(), 0);
  // A sweep without an integral (IMU samples missing) starts the window again: 10 s before the next gravity.
  GravityObserver gap;
  const Trajectory traj;
  EXPECT_GT(observe(gap, traj, 1.0, 12.0, 0.0).count, 0);
  EXPECT_FALSE(gap.add(toUtime(13.1), traj.pose(13.1), SpecificForceIntegral{}));
  EXPECT_EQ(observe(gap, traj, 13.2, 9.8, 0.0).count, 0);
  EXPECT_GT(observe(gap, traj, 23.1, 1.0, 0.0).count, 0);
}

TEST(GravityReference, TurnsTheMapAShareOfItsTiltEachWindowAboutTheRobot) {
  GravityConfig config;
  config.time_constant_s = 60.0;  // 10 s window: a sixth of the tilt each window
  GravityReference reference(config);
  const Eigen::Vector3d down(0, 0, -9.8), about(50, -3, 2);
  const Eigen::Isometry3d at{Eigen::Translation3d(about)};
  EXPECT_FALSE(reference.levelling(down, at, 0));  // the map's down is not known yet
  for (int i = 0; i < config.reference_sweeps; ++i) reference.observe(down, at);
  ASSERT_TRUE(reference.known());
  // The map has tilted 1 deg about x: a turn of 10/60 of it back, a window after the first call, about `about`.
  const Eigen::Vector3d tilted = expRotation(Eigen::Vector3d(1 * kDeg, 0, 0)) * down;
  EXPECT_FALSE(reference.levelling(tilted, at, toUtime(100.0)));
  EXPECT_FALSE(reference.levelling(tilted, at, toUtime(109.9)));
  const auto turn = reference.levelling(tilted, at, toUtime(110.0));
  ASSERT_TRUE(turn);
  EXPECT_NEAR(rotationAngle(*turn) / kDeg, 1.0 / 6.0, 1e-9);
  EXPECT_LT(angleBetween(turn->linear() * tilted, down), 1 * kDeg);
  EXPECT_NEAR((turn->linear() * tilted).normalized().dot(down.normalized()), std::cos(5.0 / 6.0 * kDeg), 1e-12);
  EXPECT_LT((*turn * about - about).norm(), 1e-12);
  EXPECT_FALSE(reference.levelling(tilted, at, toUtime(115.0)));
  // 5 deg off is not the map's drift but an accelerometer mounted otherwise than configured: no turn, counted.
  const Eigen::Vector3d askew = expRotation(Eigen::Vector3d(0, 5 * kDeg, 0)) * down;
  EXPECT_FALSE(reference.levelling(askew, at, toUtime(120.0)));
  EXPECT_EQ(reference.disagreements(), 1);
  EXPECT_TRUE(reference.levelling(tilted, at, toUtime(130.0)));
  // Off: never a turn.
  config.time_constant_s = 0.0;
  GravityReference off(config);
  for (int i = 0; i < config.reference_sweeps; ++i) off.observe(down, at);
  EXPECT_FALSE(off.levelling(tilted, at, toUtime(100.0)));
  EXPECT_FALSE(off.levelling(tilted, at, toUtime(200.0)));
}

// The accelerometer's bias (3 mg horizontal) shows in the map frame as R b: after a turn it would read as a
// tilt of up to twice bias / 9.81 (0.35 deg). Estimated where the heading changed, it is taken out.
TEST(GravityReference, EstimatesTheAccelerometersBiasWhereTheHeadingChanges) {
  GravityConfig config;
  GravityReference reference(config);
  const Eigen::Vector3d bias(0.025, -0.018, 0.0), g0(0, 0, -9.80665);
  const auto headed = [](double yaw_deg) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = expRotation(Eigen::Vector3d(0, 0, yaw_deg * kDeg));
    return T;
  };
  const auto measured = [&](const Eigen::Isometry3d& T) { return Eigen::Vector3d(g0 + T.linear() * bias); };
  for (int i = 0; i < 200; ++i) reference.observe(measured(headed(0)), headed(0));  // reference, then straight
  EXPECT_LT(reference.bias().norm(), 1e-9);  // not observable yet: the prior's zero
  for (double yaw = 0; yaw <= 180; yaw += 1.0) reference.observe(measured(headed(yaw)), headed(yaw));
  EXPECT_LT((reference.bias() - bias).head<2>().norm(), 0.002);
  // Heading back along the roadway (180 deg), no tilt: no turn beyond what the bias left (< 0.01 deg).
  const auto turn = reference.levelling(measured(headed(180)), headed(180), toUtime(100.0));
  EXPECT_FALSE(turn);  // the first a window later
  const auto later = reference.levelling(measured(headed(180)), headed(180), toUtime(110.0));
  ASSERT_TRUE(later);
  EXPECT_LT(rotationAngle(*later) / kDeg, 0.01);
  // Without the estimate the same reading is a tilt of 2 |b| / g = 0.36 deg from the reference's.
  EXPECT_NEAR(angleBetween(measured(headed(180)), measured(headed(0))) / kDeg, 2 * bias.norm() / 9.80665 / kDeg, 0.01);
}

}  // namespace
}  // namespace adit
