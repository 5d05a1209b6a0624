// Degeneracy: detected from the Jacobian in a featureless corridor (axis direction only), not in a box room,
// reported in the covariance, and held to the motion model so a wrong seed or weak, biased information does
// not drag the estimate along the axis.
#include "core/geometry.hpp"
#include "registration/degeneracy.hpp"
#include "odometry/scan_to_scan.hpp"
#include "synthetic_world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace adit {
namespace {

constexpr double kDeg = M_PI / 180.0;
const Eigen::Isometry3d kStart = test::poseFrom(0.5, 0.1, 0.0, 0.0, 0.0, 0.02);
const Eigen::Isometry3d kStep = test::poseFrom(0.5, 0.0, 0.0, 0.0, 0.0, 0.2 * kDeg);  // 5 m/s along x

TEST(Degeneracy, AnalysisFindsTheWeakDirectionOfEachBlock) {
  Matrix6d H = Matrix6d::Zero();
  const Eigen::Vector3d weak = Eigen::Vector3d(1, 1, 0).normalized();
  H.topLeftCorner<3, 3>() = 1e4 * Eigen::Matrix3d::Identity() - (1e4 - 5.0) * weak * weak.transpose();
  H.bottomRightCorner<3, 3>() = Eigen::Vector3d(1e5, 2e5, 3e5).asDiagonal();
  const DegeneracyReport r = analyzeDegeneracy(H, 0.02, 0.001);
  EXPECT_EQ(r.flags, PoseEstimate::kDegenerateTranslation);
  EXPECT_TRUE(r.translation_degenerate[0]);
  EXPECT_FALSE(r.translation_degenerate[1] || r.translation_degenerate[2]);
  EXPECT_NEAR(std::abs(r.translation_directions.col(0).dot(weak)), 1.0, 1e-9);
  EXPECT_NEAR(r.translation_eigenvalues[0], 5.0, 1e-6);
  EXPECT_NEAR(r.rotation_eigenvalues[2], 3e5, 1e-6);

  // Covariance: the weak direction gets the prior's variance, the others the inverse information.
  const Matrix6d cov = covarianceFrom(H, r, 0.1, 0.01);
  EXPECT_NEAR(weak.dot(cov.topLeftCorner<3, 3>() * weak), 0.01, 1e-4);
  EXPECT_NEAR(cov(2, 2), 1e-4, 1e-6);
  EXPECT_NEAR(cov(3, 3), 1e-5, 1e-7);

  // Nothing measured at all: everything degenerate, covariance finite.
  const DegeneracyReport none = analyzeDegeneracy(Matrix6d::Zero(), 0.02, 0.001);
  EXPECT_EQ(none.flags, PoseEstimate::kDegenerateTranslation | PoseEstimate::kDegenerateRotation);
  EXPECT_TRUE(covarianceFrom(Matrix6d::Zero(), none, 0.1, 0.01).allFinite());
}

// Runs odometry along a straight path; the first motion is given (as an IMU-flagged prior) so that the
// constant-velocity model is established. Returns the estimates of sweeps 1..n-1.
std::vector<PoseEstimate> drive(const test::World& world, int sweeps, bool degeneracy_prior,
                                const std::optional<Eigen::Isometry3d>& last_seed = std::nullopt) {
  ScanToScanConfig config;
  config.registration.degeneracy_prior = degeneracy_prior;
  ScanToScanOdometry odom(config);
  std::vector<PoseEstimate> out;
  Eigen::Isometry3d truth = kStart;
  for (int i = 0; i < sweeps; ++i, truth = truth * kStep) {
    const FeatureSet f = test::simulateSweep(world, truth, {}, i * 100000, 100 + i);
    if (i == 1)
      out.push_back(odom.process(f, kStep, PoseEstimate::kSeededByImu));
    else if (i == sweeps - 1 && last_seed)
      out.push_back(odom.process(f, *last_seed, PoseEstimate::kSeededByLinK3d));
    else if (i > 0)
      out.push_back(odom.process(f));
    else
      odom.process(f);
  }
  return out;
}

TEST(Degeneracy, CorridorAxisIsFlaggedAndInflatedInTheCovariance) {
  const auto estimates = drive(test::featurelessCorridor(), 3, true);
  for (const PoseEstimate& e : estimates) {
    EXPECT_TRUE(e.flags & PoseEstimate::kDegenerateTranslation);
    EXPECT_FALSE(e.flags & PoseEstimate::kDegenerateRotation);
    EXPECT_FALSE(e.flags & PoseEstimate::kRegistrationFailed);
    // Measured: smallest / largest translation eigenvalue ~0.004 (threshold 0.02).
    EXPECT_LT(e.translation_eigenvalues[0], 0.01 * e.translation_eigenvalues[2]);
    // The sensor looks along the corridor (x): variance along x far above y (measured ~200x).
    EXPECT_GT(e.covariance(0, 0), 50.0 * e.covariance(1, 1));
    EXPECT_GT(e.covariance(0, 0), 10.0 * e.covariance(2, 2));  // measured ~25x: z only by floor and roof
  }
}

TEST(Degeneracy, BoxRoomIsNotDegenerate) {
  for (const PoseEstimate& e : drive(test::boxRoom(), 3, true)) {
    EXPECT_EQ(e.flags & (PoseEstimate::kDegenerateTranslation | PoseEstimate::kDegenerateRotation), 0);
    EXPECT_GT(e.translation_eigenvalues[0], 0.05 * e.translation_eigenvalues[2]);  // measured ~0.15
  }
}

TEST(Degeneracy, PriorHoldsTheAxisAgainstAWrongSeed) {
  // A LinK3D seed 0.3 m off along the unobservable axis: with the directional prior the estimate returns
  // to the motion model; plain A-LOAM (no prior) keeps most of the error. Lateral accuracy is unaffected.
  const Eigen::Isometry3d wrong = kStep * test::poseFrom(0.3, 0, 0, 0, 0, 0);
  const auto held = drive(test::featurelessCorridor(), 4, true, wrong);
  const auto loose = drive(test::featurelessCorridor(), 4, false, wrong);
  const auto lastMotionError = [](const std::vector<PoseEstimate>& e) {
    const Eigen::Isometry3d motion = e[e.size() - 2].pose.inverse() * e.back().pose;
    return Eigen::Vector3d((kStep.inverse() * motion).translation());
  };
  const Eigen::Vector3d held_error = lastMotionError(held), loose_error = lastMotionError(loose);
  EXPECT_TRUE(held.back().flags & PoseEstimate::kSeededByLinK3d);
  EXPECT_TRUE(held.back().flags & PoseEstimate::kDegenerateTranslation);
  std::printf("wrong seed residual error along axis: %.4f m with prior, %.4f m without\n", held_error.x(),
              loose_error.x());
  // Measured: 0.2 mm with the prior, 0.22 m without.
  EXPECT_LT(std::abs(held_error.x()), 0.02);
  EXPECT_GT(std::abs(loose_error.x()), 0.1);
  EXPECT_LT(held_error.tail<2>().norm(), 0.01);
}

TEST(Degeneracy, AxisDriftIsBoundedComparedWithNoPrior) {
  const auto run = [](bool prior) -> Eigen::Vector3d {
    const auto est = drive(test::featurelessCorridor(), 16, prior);
    // Per-sweep motions are relative; their product is the odometry from sweep 1 to the end.
    Eigen::Isometry3d odom = Eigen::Isometry3d::Identity();
    for (std::size_t i = 1; i < est.size(); ++i) odom = odom * (est[i - 1].pose.inverse() * est[i].pose);
    Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
    for (std::size_t i = 1; i < est.size(); ++i) truth = truth * kStep;
    return (truth.inverse() * odom).translation();
  };
  const Eigen::Vector3d with_prior = run(true), without = run(false);
  std::printf("corridor axis drift over 7 m: %.4f m with prior, %.4f m without\n", with_prior.x(), without.x());
  // Measured over 7 m: ~1 cm with the prior, ~4.3 m without (the ring pattern, which moves with the sensor,
  // pulls the estimate towards "no motion").
  EXPECT_LT(std::abs(with_prior.x()), 0.05);
  EXPECT_GT(std::abs(without.x()), 5.0 * std::abs(with_prior.x()));
}

// With an IMU the feature stage seeds each sweep with the gyro's rotation and the last step's translation.
// Where the axis turns degenerate it must hold the velocity averaged over the observed sweeps, as without an
// IMU, not that last step: one step is as noisy as the sweep it came from, and held for the rest of a
// featureless stretch its error becomes the stretch's error (the 320 m featureless world: held 7 % above the
// speed at entry, 10.5 % end-point error; with the average 3.0 %). Here the robot's steps alternate 0.13 /
// 0.17 m (a jerky crawler, 1.5 m/s on average) past pillars that leave the lidar's 15 m range at x ~ 26 m.
TEST(Degeneracy, WithAnImuPriorTheAxisHoldsTheAveragedSpeedNotTheLastStep) {
  test::World world;
  world.boxes.push_back({{-50, -2.5, -1.2}, {400, 2.5, 2.5}, true});
  test::addWallPillars(world, -40, 10, 3.0);
  test::LidarModel lidar;
  lidar.max_range = 15.0;
  ScanToScanOdometry odom;
  double x = 0.0, zone_start_truth = -1.0, zone_start_est = 0.0, est_x = 0.0;
  Eigen::Isometry3d last_pose = Eigen::Isometry3d::Identity();
  int degenerate = 0, zone_sweeps = 0;
  for (int i = 0; x < 75.0; ++i) {
    if (i > 0) x += (i % 2 == 1) ? 0.13 : 0.17;
    const FeatureSet f = test::simulateSweep(world, test::poseFrom(x, 0.1, 0.0, 0, 0, 0), lidar, i * 100000, 500 + i);
    // What the feature stage seeds with when an IMU covers the interval: its rotation (here exact, none)
    // and the odometry's constant-velocity translation.
    Eigen::Isometry3d imu_seed = odom.predictMotion(f.utime);
    imu_seed.linear().setIdentity();
    const PoseEstimate e = i < 2 ? odom.process(f) : odom.process(f, imu_seed, PoseEstimate::kSeededByImu);
    if (i > 0) est_x += (last_pose.inverse() * e.pose).translation().x();
    last_pose = e.pose;
    if (x < 30.0) continue;  // the zone: pillars beyond range (the last one ends at x = 10.5)
    if (zone_start_truth < 0.0) zone_start_truth = x, zone_start_est = est_x;
    ++zone_sweeps;
    if (e.flags & PoseEstimate::kDegenerateTranslation) ++degenerate;
  }
  const double zone = x - zone_start_truth, error = (est_x - zone_start_est) - zone;
  std::printf("jerky crawler, IMU-seeded: %.1f m in the zone, %d of %d sweeps degenerate, axial error %+.2f m "
              "(%.1f %%)\n", zone, degenerate, zone_sweeps, error, 100.0 * error / zone);
  EXPECT_GT(degenerate, 0.9 * zone_sweeps);
  // Measured: +2.7 %, as without an IMU (what is left is the averaged speed's own error from the sweeps that
  // observed the axis); held to the last step +9.0 %.
  EXPECT_LT(std::abs(error), 0.05 * zone);
}

}  // namespace
}  // namespace adit
