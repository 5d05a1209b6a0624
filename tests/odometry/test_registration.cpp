// Scan-to-scan and scan-to-map registration recover known rigid transforms between synthetic sweeps, and
// survive empty or corrupt input.
#include "core/geometry.hpp"
#include "mapping/scan_to_map.hpp"
#include "odometry/scan_to_scan.hpp"
#include "synthetic_world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace adit {
namespace {

constexpr double kDeg = M_PI / 180.0;

double rotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return rotationAngle(a.inverse() * b) / kDeg;
}
double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.inverse() * b).translation().norm();
}

// Moves every point of a FeatureSet by T (for "transformed copy" tests).
FeatureSet transformedCopy(const FeatureSet& f, const Eigen::Isometry3d& T, std::int64_t utime) {
  FeatureSet g = f;
  g.utime = utime;
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (auto* set : {&g.cloud.points, &g.corner_sharp, &g.corner_less_sharp, &g.surf_flat, &g.surf_less_flat})
    for (LidarPoint& p : *set) p.p = Tf * p.p;
  return g;
}

const Eigen::Isometry3d kStart = test::poseFrom(0.5, -0.3, 0.2, 0.0, 0.0, 0.3);
const Eigen::Isometry3d kMotion = test::poseFrom(0.4, -0.2, 0.05, 1.0 * kDeg, -0.5 * kDeg, 3.0 * kDeg);

TEST(ScanToScan, RecoversTransformOfExactCopy) {
  const auto world = test::boxRoom();
  const FeatureSet a = test::simulateSweep(world, kStart, {}, 0, 1);
  // Points seen from the moved sensor: p_curr = T_prev_curr^-1 * p_prev.
  const FeatureSet b = transformedCopy(a, kMotion.inverse(), 100000);
  ScanToScanOdometry odom;
  odom.process(a);
  const PoseEstimate e = odom.process(b);
  EXPECT_EQ(e.flags & PoseEstimate::kRegistrationFailed, 0);
  // Not exactly zero: lines and planes are least-squares fits to several noisy neighbours, not through the
  // matched point itself (measured 0.3 mm, 0.011 deg).
  EXPECT_LT(translationError(e.pose, kMotion), 2e-3);
  EXPECT_LT(rotationErrorDeg(e.pose, kMotion), 0.03);
}

TEST(ScanToScan, RecoversTransformBetweenIndependentSweeps) {
  const auto world = test::boxRoom();
  ScanToScanOdometry odom;
  odom.process(test::simulateSweep(world, kStart, {}, 0, 1));
  const PoseEstimate e = odom.process(test::simulateSweep(world, kStart * kMotion, {}, 100000, 2));
  EXPECT_EQ(e.flags & PoseEstimate::kRegistrationFailed, 0);
  EXPECT_EQ(e.flags & (PoseEstimate::kDegenerateTranslation | PoseEstimate::kDegenerateRotation), 0);
  EXPECT_LT(translationError(e.pose, kMotion), 0.02);
  EXPECT_LT(rotationErrorDeg(e.pose, kMotion), 0.2);
  // Well-conditioned: covariance small and positive definite.
  EXPECT_GT(e.covariance.diagonal().minCoeff(), 0.0);
  const double max_translation_variance = e.covariance.topLeftCorner<3, 3>().diagonal().maxCoeff();
  EXPECT_LT(max_translation_variance, 1e-3);
  EXPECT_GT(e.translation_eigenvalues[0], 0.0);
}

TEST(ScanToScan, UsesSeedForLargeMotion) {
  // 2.5 m and 10 degrees between sweeps: a near-correct seed (e.g. LinK3D) makes it converge.
  const auto world = test::boxRoom();
  const Eigen::Isometry3d big = test::poseFrom(2.5, 0.6, 0.0, 0.0, 0.0, 10.0 * kDeg);
  ScanToScanOdometry odom;
  odom.process(test::simulateSweep(world, kStart, {}, 0, 1));
  const Eigen::Isometry3d seed = big * test::poseFrom(0.15, -0.1, 0.0, 0.0, 0.0, 1.0 * kDeg);
  const PoseEstimate e =
      odom.process(test::simulateSweep(world, kStart * big, {}, 100000, 2), seed, PoseEstimate::kSeededByLinK3d);
  EXPECT_TRUE(e.flags & PoseEstimate::kSeededByLinK3d);
  // Independent sweeps of a 16-beam lidar: ~1 cm / ~0.1 deg is the floor set by features near wall-floor
  // junctions, whose neighbours straddle two faces (measured 0.8 cm, 0.13 deg).
  EXPECT_LT(translationError(e.pose, big), 0.02);
  EXPECT_LT(rotationErrorDeg(e.pose, big), 0.2);
}

TEST(ScanToScan, ConstantVelocityTracksASequence) {
  const auto world = test::boxRoom();
  ScanToScanOdometry odom;
  const Eigen::Isometry3d step = test::poseFrom(0.3, 0.05, 0.0, 0.0, 0.0, 1.5 * kDeg);
  Eigen::Isometry3d truth = kStart;
  for (int i = 0; i < 8; ++i) {
    const PoseEstimate e = odom.process(test::simulateSweep(world, truth, {}, i * 100000, 10 + i));
    EXPECT_EQ(e.flags & PoseEstimate::kRegistrationFailed, 0) << "sweep " << i;
    EXPECT_TRUE(e.flags & PoseEstimate::kSeededByMotionModel);
    truth = truth * step;
  }
  const Eigen::Isometry3d truth_end = kStart.inverse() * (truth * step.inverse());
  // Seven registrations (measured 0.29 deg accumulated).
  EXPECT_LT(translationError(odom.pose(), truth_end), 0.05);
  EXPECT_LT(rotationErrorDeg(odom.pose(), truth_end), 0.5);
}

// Standing still, each noisy sweep registered against the previous one adds its own error; against the
// reference sweep kept while the robot has not moved (keep_reference_within_*) the error stays that of one
// registration. Driving, the reference is the previous sweep.
TEST(ScanToScan, AtRestTheReferenceSweepIsKeptAndErrorsDoNotAddUp) {
  const auto world = test::boxRoom();
  test::LidarModel noisy;
  noisy.range_noise = 0.03;
  const auto worstAtRest = [&](const ScanToScanConfig& config, bool* kept) {
    ScanToScanOdometry odom(config);
    double worst = 0.0;
    for (int i = 0; i < 60; ++i) {
      const PoseEstimate e = odom.process(test::simulateSweep(world, kStart, noisy, i * 100000, 100 + i));
      worst = std::max(worst, translationError(Eigen::Isometry3d::Identity(), e.pose));
      if (i > 0) *kept = *kept && odom.referenceKept();
    }
    return worst;
  };
  bool kept = true, kept_off = true;
  const double with_reference = worstAtRest(ScanToScanConfig{}, &kept);
  ScanToScanConfig previous_only;
  previous_only.keep_reference_within_m = 0.0;
  const double without = worstAtRest(previous_only, &kept_off);
  std::printf("at rest, 60 noisy sweeps: worst %.2f mm against the kept reference, %.2f mm sweep to sweep\n",
              1e3 * with_reference, 1e3 * without);
  EXPECT_TRUE(kept);
  EXPECT_FALSE(kept_off);
  EXPECT_LT(with_reference, 0.5 * without);

  ScanToScanOdometry driving;
  const Eigen::Isometry3d step = test::poseFrom(0.2, 0.0, 0.0, 0.0, 0.0, 0.0);
  Eigen::Isometry3d truth = kStart;
  for (int i = 0; i < 4; ++i, truth = truth * step) {
    driving.process(test::simulateSweep(world, truth, {}, i * 100000, 10 + i));
    EXPECT_FALSE(driving.referenceKept()) << "sweep " << i;
  }
}

// Standing still (odometry.standstill): after a window of still registrations the reported position is their
// mean, flagged kStandingStill, while each sweep still registers from its own estimate (pose()).
TEST(ScanToScan, StandingStillReportsTheMeanPositionOfItsRegistrations) {
  const auto world = test::boxRoom();
  test::LidarModel noisy;
  noisy.range_noise = 0.03;
  const int window = ScanToScanConfig{}.standstill.window_sweeps;
  ScanToScanOdometry odom;
  Eigen::Isometry3d first_held = Eigen::Isometry3d::Identity();
  double reported_moved = 0, registered_moved = 0;
  for (int i = 0; i < 60; ++i) {
    const PoseEstimate e = odom.process(test::simulateSweep(world, kStart, noisy, i * 100000, 700 + i));
    EXPECT_EQ(static_cast<bool>(e.flags & PoseEstimate::kStandingStill), i >= window) << i;  // 0: first sweep
    if (i == window) first_held = e.pose;
    if (i <= window) continue;
    reported_moved = std::max(reported_moved, translationError(first_held, e.pose));
    registered_moved = std::max(registered_moved, translationError(first_held, odom.pose()));
    EXPECT_LT(rotationErrorDeg(e.pose, odom.pose()), 1e-9) << i;  // the rotation is the registration's
  }
  std::printf("at rest, 60 noisy sweeps: reported position moved %.2f mm, registrations %.2f mm\n",
              1e3 * reported_moved, 1e3 * registered_moved);
  EXPECT_LT(reported_moved, 0.3 * registered_moved);

  ScanToScanConfig off;
  off.standstill.window_sweeps = 0;
  ScanToScanOdometry unheld(off);
  for (int i = 0; i < 30; ++i) {
    const PoseEstimate e = unheld.process(test::simulateSweep(world, kStart, noisy, i * 100000, 700 + i));
    EXPECT_FALSE(e.flags & PoseEstimate::kStandingStill);
    EXPECT_TRUE(e.pose.isApprox(unheld.pose()));
  }
}

// At rest with a gyro whose bias is not quite removed: the weighed gyro's step starts from the previous estimate
// against the kept reference, so its prior carries that estimate's uncertainty too, and the lidar's view of the
// reference keeps the rotation from walking with the bias (held to the step's sigma alone it walked 0.44 deg in
// 30 s here, half the 0.86 deg of bias error; an idling robot's roll 0.6 deg a minute in the simulator).
TEST(ScanToScan, AtRestAGyroBiasErrorDoesNotAddUp) {
  const auto world = test::boxRoom();
  test::LidarModel noisy;
  noisy.range_noise = 0.03;
  ScanToScanOdometry odom;
  const double bias = 5e-4, dt = 0.1;  // rad/s left in the gyro's roll, s between sweeps
  RotationPrior gyro;
  gyro.R = Eigen::AngleAxisd(bias * dt, Eigen::Vector3d::UnitX()).toRotationMatrix();
  gyro.sigma_rad = 1e-4;
  double worst_deg = 0.0;
  const int sweeps = 300;
  for (int i = 0; i < sweeps; ++i) {
    const PoseEstimate e = odom.process(test::simulateSweep(world, kStart, noisy, i * 100000, 300 + i), std::nullopt,
                                        0, std::nullopt, i > 0 ? std::optional<RotationPrior>(gyro) : std::nullopt);
    worst_deg = std::max(worst_deg, Eigen::AngleAxisd(e.pose.linear()).angle() * 180.0 / M_PI);
  }
  const double integrated_deg = bias * dt * (sweeps - 1) * 180.0 / M_PI;
  std::printf("at rest, gyro bias error %.1e rad/s over %d sweeps: worst rotation %.3f deg (integrated %.2f deg)\n",
              bias, sweeps, worst_deg, integrated_deg);
  EXPECT_TRUE(odom.referenceKept());
  EXPECT_LT(worst_deg, 0.1 * integrated_deg);
}

TEST(ScanToScan, EmptyAndCorruptSweepsAreFlaggedNotFatal) {
  const auto world = test::boxRoom();
  ScanToScanOdometry odom;
  odom.process(test::simulateSweep(world, kStart, {}, 0, 1));
  FeatureSet empty;
  empty.utime = 100000;
  const Eigen::Isometry3d prior = test::poseFrom(0.1, 0, 0, 0, 0, 0);
  const PoseEstimate e = odom.process(empty, prior, PoseEstimate::kSeededByImu);
  EXPECT_TRUE(e.flags & PoseEstimate::kRegistrationFailed);
  EXPECT_LT(translationError(e.pose, prior), 1e-12);  // kept the prior
  EXPECT_TRUE(e.covariance.allFinite());

  FeatureSet nan = test::simulateSweep(world, kStart, {}, 200000, 2);
  for (LidarPoint& p : nan.surf_flat) p.p.x() = std::numeric_limits<float>::quiet_NaN();
  for (LidarPoint& p : nan.corner_less_sharp) p.p.y() = std::numeric_limits<float>::infinity();
  const PoseEstimate n = odom.process(nan);
  EXPECT_TRUE(n.pose.matrix().allFinite());
  EXPECT_TRUE(n.covariance.allFinite());
  const PoseEstimate nonfinite_prior =
      odom.process(test::simulateSweep(world, kStart, {}, 300000, 3),
                   Eigen::Isometry3d(Eigen::Translation3d(std::nan(""), 0, 0)), PoseEstimate::kSeededByLinK3d);
  EXPECT_TRUE(nonfinite_prior.pose.matrix().allFinite());
}

TEST(ScanToScan, IsDeterministic) {
  const auto world = test::boxRoom();
  const auto run = [&] {
    ScanToScanOdometry odom;
    Eigen::Isometry3d truth = kStart;
    PoseEstimate last;
    for (int i = 0; i < 4; ++i, truth = truth * kMotion) last = odom.process(test::simulateSweep(world, truth, {}, i * 100000, 5 + i));
    return last;
  };
  const PoseEstimate a = run(), b = run();
  EXPECT_EQ(0, std::memcmp(a.pose.data(), b.pose.data(), sizeof(double) * 16));
  EXPECT_EQ(0, std::memcmp(a.covariance.data(), b.covariance.data(), sizeof(double) * 36));
}

TEST(ScanToMap, RefinesAPoorOdometryGuessAgainstTheMap) {
  const auto world = test::boxRoom();
  ScanToMapMapper mapper;
  PoseEstimate odom;
  odom.pose = kStart;
  mapper.process(test::simulateSweep(world, kStart, {}, 0, 1), odom);
  // Odometry claims the robot did not move; it moved by kMotion.
  odom.utime = 100000;
  const PoseEstimate e = mapper.process(test::simulateSweep(world, kStart * kMotion, {}, 100000, 2), odom);
  EXPECT_EQ(e.flags & PoseEstimate::kRegistrationFailed, 0);
  EXPECT_LT(translationError(e.pose, kStart * kMotion), 0.02);
  EXPECT_LT(rotationErrorDeg(e.pose, kStart * kMotion), 0.2);
  EXPECT_GT(mapper.surfMap().numPoints(), 1000u);
  EXPECT_GT(mapper.cornerMap().numPoints(), 50u);
}

TEST(ScanToMap, EmptySweepKeepsThePrediction) {
  const auto world = test::boxRoom();
  ScanToMapMapper mapper;
  PoseEstimate odom;
  odom.pose = kStart;
  mapper.process(test::simulateSweep(world, kStart, {}, 0, 1), odom);
  FeatureSet empty;
  odom.pose = kStart * kMotion;
  const PoseEstimate e = mapper.process(empty, odom);
  EXPECT_TRUE(e.flags & PoseEstimate::kRegistrationFailed);
  EXPECT_LT(translationError(e.pose, kStart * kMotion), 1e-9);
}

}  // namespace
}  // namespace adit
