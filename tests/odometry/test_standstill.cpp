// StandstillHold (odometry/standstill.hpp): a robot standing still reports the mean of its registrations, and
// only while it stands. Registrations are the truth plus a noise as a noisy 16-beam lidar's at rest (~3 mm a
// sweep per axis, measured on the simulator's worlds), 10 sweeps a second.
#include "core/geometry.hpp"
#include "odometry/standstill.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace adit {
namespace {

constexpr std::int64_t kSweepUs = 100000;
constexpr double kNoiseM = 0.003, kNoiseRad = 0.0005;

struct Noise {
  std::mt19937 rng{7};
  std::normal_distribution<double> normal;
  Eigen::Isometry3d operator()(const Eigen::Isometry3d& truth) {
    Eigen::Isometry3d T = truth;
    T.translation() += kNoiseM * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    T.linear() = T.linear() * expRotation(kNoiseRad * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
    return T;
  }
};

Eigen::Isometry3d poseAt(double x, double yaw = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = expRotation(Eigen::Vector3d(0, 0, yaw));
  T.translation() = Eigen::Vector3d(100.0 + x, -40.0, 2.0);
  return T;
}

TEST(StandstillHold, AtRestReportsTheMeanOfItsRegistrations) {
  StandstillHold hold;
  Noise noise;
  double worst_registered = 0, worst_reported = 0, worst_turn_difference = 0;
  for (int i = 0; i < 600; ++i) {
    const Eigen::Isometry3d registered = noise(poseAt(0));
    const Eigen::Isometry3d reported = hold.update(i * kSweepUs, registered);
    EXPECT_EQ(hold.holding(), i >= StandstillConfig{}.window_sweeps - 1) << i;
    if (!hold.holding()) continue;
    worst_registered = std::max(worst_registered, translationNorm(poseAt(0).inverse() * registered));
    worst_reported = std::max(worst_reported, (reported.translation() - poseAt(0).translation()).norm());
    // The rotation is each registration's own (an idling chassis rocks, and the lidar sees it).
    worst_turn_difference = std::max(worst_turn_difference, rotationAngle(reported.inverse() * registered));
  }
  // 3 mm a sweep per axis: single registrations stray ~1.5 cm; the mean of 20 or more stays within ~2 mm.
  EXPECT_GT(worst_registered, 0.01);
  EXPECT_LT(worst_reported, 0.003);
  EXPECT_LT(worst_turn_difference, 1e-9);
}

TEST(StandstillHold, NeverHoldsARobotCreepingAtTwoCentimetresASecond) {
  StandstillHold hold;
  Noise noise;
  for (int i = 0; i < 600; ++i) {
    const Eigen::Isometry3d registered = noise(poseAt(0.002 * i));
    EXPECT_TRUE(hold.update(i * kSweepUs, registered).isApprox(registered)) << i;
    EXPECT_FALSE(hold.holding()) << i;
  }
}

TEST(StandstillHold, NeverHoldsARobotTurningInPlace) {
  StandstillHold hold;
  Noise noise;
  for (int i = 0; i < 600; ++i) {  // 0.6 deg/s, round one and a half turns of the rotation vector's range
    hold.update(i * kSweepUs, noise(poseAt(0, 0.001 * i)));
    EXPECT_FALSE(hold.holding()) << i;
  }
}

// Pulling away at 0.3 m/s^2 after 5 s at rest: the reported position stays within 3 cm of the truth, the hold
// ends within 0.6 s (the robot 5.4 cm away), and from then on every registration is reported as it is.
TEST(StandstillHold, LetsGoOfARobotPullingAway) {
  StandstillHold hold;
  Noise noise;
  int released = -1;
  for (int i = 0; i < 100; ++i) {
    const double t = std::max(0.0, 0.1 * i - 5.0);
    const Eigen::Isometry3d truth = poseAt(0.15 * t * t);
    const Eigen::Isometry3d registered = noise(truth);
    const Eigen::Isometry3d reported = hold.update(i * kSweepUs, registered);
    if (i < 50) {
      EXPECT_EQ(hold.holding(), i >= 19) << i;
    }
    if (i >= 50 && released < 0 && !hold.holding()) released = i;
    if (released >= 0) {
      EXPECT_FALSE(hold.holding()) << i;
      EXPECT_TRUE(reported.isApprox(registered)) << i;
    } else {
      EXPECT_LT((reported.translation() - truth.translation()).norm(), 0.03) << i;
    }
  }
  ASSERT_GE(released, 50);
  EXPECT_LE(released, 56);
}

TEST(StandstillHold, HeldPoseMovesWithALoopCorrection) {
  StandstillHold a, b;
  Noise noise_a, noise_b;
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  correction.linear() = expRotation(Eigen::Vector3d(0.01, -0.02, 0.7));
  correction.translation() = Eigen::Vector3d(-3.0, 1.5, 0.2);
  for (int i = 0; i < 60; ++i) {
    // b sees every registration corrected from the start; a is corrected half-way.
    if (i == 30) a.applyCorrection(correction);
    const Eigen::Isometry3d ra = noise_a(poseAt(0));
    const Eigen::Isometry3d rb = correction * noise_b(poseAt(0));
    const Eigen::Isometry3d pa = a.update(i * kSweepUs, i >= 30 ? correction * ra : ra);
    const Eigen::Isometry3d pb = b.update(i * kSweepUs, rb);
    if (i >= 30) {
      EXPECT_TRUE(a.holding());
      EXPECT_LT((pa.translation() - pb.translation()).norm(), 1e-9) << i;
    }
  }
}

TEST(StandstillHold, OffReportsEveryRegistration) {
  StandstillConfig config;
  config.window_sweeps = 0;
  StandstillHold hold(config);
  Noise noise;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Isometry3d registered = noise(poseAt(0));
    EXPECT_TRUE(hold.update(i * kSweepUs, registered).isApprox(registered));
    EXPECT_FALSE(hold.holding());
  }
}

}  // namespace
}  // namespace adit
