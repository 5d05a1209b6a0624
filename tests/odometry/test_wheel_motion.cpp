// Wheel odometry as the motion along degenerate directions (odometry/wheel_motion.hpp): the integration over a
// sweep interval, the slip calibration against the lidar, and bad input (gaps, NaN, unordered stamps, a
// frozen value, a wheel that disagrees with the lidar) detected, counted and kept out.
#include "odometry/wheel_motion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace adit {
namespace {

constexpr std::int64_t kStart = 1'000'000'000;
constexpr std::int64_t kStep = 20'000;  // 50 Hz

// Readings from t0 - 20 ms to t1 + 20 ms of a constant speed and yaw rate, with a tiny alternating jitter
// (a real encoder's value is never the same to the bit while moving).
std::vector<WheelOdomSample> readings(std::int64_t t0, std::int64_t t1, double speed, double yaw_rate) {
  std::vector<WheelOdomSample> r;
  for (std::int64_t t = t0 - kStep; t <= t1 + kStep; t += kStep)
    r.push_back({t, speed + ((t / kStep) % 2 ? 1e-6 : -1e-6), yaw_rate, 0.0, 0.0});
  return r;
}

Eigen::Isometry3d forward(double metres) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().x() = metres;
  return T;
}

TEST(WheelMotion, IntegratesAnArcOverTheInterval) {
  WheelMotion wheel;
  const std::int64_t t0 = kStart, t1 = kStart + 100'000;
  const auto m = wheel.motion(readings(t0, t1, 1.0, 0.5), t0, t1);
  ASSERT_TRUE(m);
  // 0.1 m along an arc of radius 2 m: chord at half the 0.05 rad turned.
  EXPECT_NEAR(m->T_prev_curr.translation().x(), 2.0 * std::sin(0.05), 1e-5);
  EXPECT_NEAR(m->T_prev_curr.translation().y(), 2.0 * (1.0 - std::cos(0.05)), 1e-5);
  EXPECT_NEAR(Eigen::AngleAxisd(m->T_prev_curr.linear()).angle(), 0.05, 1e-6);
  // Uncalibrated: the scale's uncertainty (8 % of 0.1 m) dominates.
  EXPECT_NEAR(m->sigma_translation_m, 0.008, 0.001);
}

TEST(WheelMotion, MountRotationPutsTheForwardAxisWhereTheBaseIs) {
  WheelMotionConfig c;
  c.mount_rpy_deg = Eigen::Vector3f(0, 0, 90);  // base x = lidar y
  WheelMotion wheel(c);
  const auto m = wheel.motion(readings(kStart, kStart + 100'000, 1.0, 0.0), kStart, kStart + 100'000);
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->T_prev_curr.translation().y(), 0.1, 1e-6);
  EXPECT_NEAR(m->T_prev_curr.translation().x(), 0.0, 1e-6);
}

TEST(WheelMotion, CalibratesSlipWhereTheLidarObservesTheMotion) {
  WheelMotion wheel;
  // The tracks slip 6 %: the wheel says 1.06 m/s while the robot does 1.0 m/s.
  std::int64_t t = kStart;
  for (int i = 0; i < 400; ++i, t += 100'000) {
    const auto m = wheel.motion(readings(t, t + 100'000, 1.06, 0.0), t, t + 100'000);
    ASSERT_TRUE(m);
    wheel.observe(forward(0.1), 1.0, 0.1, m);
  }
  EXPECT_TRUE(wheel.calibrated());
  EXPECT_NEAR(wheel.scale(), 1.0 / 1.06, 1e-4);
  // Degenerate sweeps do not calibrate: a lidar that sees nothing along the axis says nothing about slip.
  const auto m = wheel.motion(readings(t, t + 100'000, 1.06, 0.0), t, t + 100'000);
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->distance_m, 0.1, 1e-4);
  wheel.observe(forward(0.0), 0.0, 0.1, m);
  EXPECT_NEAR(wheel.scale(), 1.0 / 1.06, 1e-4);
  EXPECT_EQ(wheel.counters().calibrations, 400);
}

TEST(WheelMotion, GapsNonFiniteAndUnorderedReadingsAreCountedNotUsed) {
  WheelMotion wheel;
  const std::int64_t t0 = kStart, t1 = kStart + 100'000;
  auto r = readings(t0, t1, 1.0, 0.0);
  // Only a reading 20 ms before the interval: nothing within max_gap_s (0.1 s) of its end.
  EXPECT_FALSE(wheel.motion({r.begin(), r.begin() + 1}, t0, t1));
  EXPECT_EQ(wheel.counters().gaps, 1);
  // NaN readings are skipped; the others still cover the interval.
  WheelMotion w2;
  r[3].speed = std::numeric_limits<double>::quiet_NaN();
  auto later = r[5];
  later.utime = r[2].utime;  // time going backwards
  r.insert(r.begin() + 5, later);
  const auto m = w2.motion(r, t0, t1);
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->T_prev_curr.translation().x(), 0.1, 1e-4);
  EXPECT_EQ(w2.counters().nonfinite, 1);
  EXPECT_EQ(w2.counters().unordered, 1);
}

TEST(WheelMotion, FrozenSpeedWhileMovingIsDistrusted) {
  WheelMotion wheel;
  std::int64_t t = kStart;
  int used = 0, refused = 0;
  for (int i = 0; i < 30; ++i, t += 100'000) {  // 3 s of exactly 1.0 m/s, to the bit
    std::vector<WheelOdomSample> r = readings(t, t + 100'000, 1.0, 0.0);
    for (auto& s : r) s.speed = 1.0;
    const auto m = wheel.motion(r, t, t + 100'000);
    (m ? used : refused)++;
    wheel.observe(forward(0.1), 1.0, 0.1, m);
  }
  // Used until the value has not changed for stuck_after_s (1 s), refused from then on.
  EXPECT_GE(used, 9);
  EXPECT_LE(used, 11);
  EXPECT_EQ(wheel.counters().stuck, refused);
  // Standing still, a constant zero is what an encoder says: not stuck.
  WheelMotion still;
  for (int i = 0; i < 30; ++i, t += 100'000) {
    std::vector<WheelOdomSample> r = readings(t, t + 100'000, 0.0, 0.0);
    for (auto& s : r) s.speed = 0.0;
    const auto m = still.motion(r, t, t + 100'000);
    EXPECT_TRUE(m);
    still.observe(forward(0.0), 1.0, 0.1, m);
  }
  EXPECT_EQ(still.counters().stuck, 0);
}

TEST(WheelMotion, DisagreementWithTheLidarKeepsTheWheelOutForAWhile) {
  WheelMotion wheel;
  std::int64_t t = kStart;
  // The track spins on mud: the wheel says 2 m/s, the lidar sees 1 m/s.
  auto m = wheel.motion(readings(t, t + 100'000, 2.0, 0.0), t, t + 100'000);
  ASSERT_TRUE(m);
  wheel.observe(forward(0.1), 1.0, 0.1, m);
  EXPECT_EQ(wheel.counters().disagreements, 1);
  EXPECT_EQ(wheel.counters().calibrations, 0);
  EXPECT_NEAR(wheel.scale(), 1.0, 1e-12);  // the bad ratio did not enter the scale
  int refused = 0;
  for (int i = 1; i <= 30; ++i) {
    t += 100'000;
    m = wheel.motion(readings(t, t + 100'000, 1.0, 0.0), t, t + 100'000);
    if (!m) ++refused;
    wheel.observe(forward(0.1), 1.0, 0.1, m);
  }
  EXPECT_NEAR(refused, 20, 1);  // distrust_s = 2 s, then used (and calibrated) again
  EXPECT_GT(wheel.counters().calibrations, 5);
}

}  // namespace
}  // namespace adit
