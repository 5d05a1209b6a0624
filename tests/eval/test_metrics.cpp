// APE / RPE / drift on hand-made trajectories with answers known in closed form.
//
// Definitions matched (evo 1.x, core/metrics.py + core/filters.py; KITTI odometry devkit):
//  - APE translation part: |p_est - p_gt| after alignment; stats as numpy: population std (ddof=0),
//    median = mean of the two middle values for an even count.
//  - RPE: E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j), consecutive pairs (all_pairs = false), pairs chosen on the
//    ESTIMATE (pairs_from_reference = false), delta in metres of accumulated path; evo's quirk kept:
//    the first recorded index is where the path first reaches delta, not index 0.
//  - KITTI drift: devkit calcSequenceErrors (first frames every 10, last frame = first with gt
//    distance > start + L, error divided by the nominal L).
#include "eval/evaluate.hpp"
#include "eval/metrics.hpp"
#include "fixtures.hpp"

#include <gtest/gtest.h>

#include <random>

namespace adit::eval {
namespace {

using test::transformed;

TEST(ErrorStats, MatchesNumpyDefinitions) {
  // numpy on [1, 2, 3, 4]: mean 2.5, median 2.5, std (ddof=0) sqrt(1.25), rmse sqrt(7.5).
  const ErrorStats s = computeStats({4.0, 1.0, 3.0, 2.0});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_NEAR(s.std, std::sqrt(1.25), 1e-15);
  EXPECT_NEAR(s.rmse, std::sqrt(7.5), 1e-15);
  EXPECT_DOUBLE_EQ(computeStats({3.0, 1.0, 2.0}).median, 2.0);
  EXPECT_EQ(computeStats({}).count, 0u);
}

TEST(Ape, PureOffsetIsItsNormWithoutAlignmentAndZeroWithSe3) {
  const Trajectory gt = test::windingPath(300);
  const Trajectory est = transformed(gt, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.3, -0.4, 1.2));
  const double offset = std::sqrt(0.09 + 0.16 + 1.44);  // 1.3 m

  EvalConfig none;
  none.align = AlignMode::kNone;
  const EvalResult a = evaluate(gt, est, none);
  ASSERT_TRUE(a.valid);
  EXPECT_EQ(a.matched_poses, 300u);
  for (double v : {a.ape_m.max, a.ape_m.min, a.ape_m.mean, a.ape_m.median, a.ape_m.rmse}) EXPECT_NEAR(v, offset, 1e-12);
  EXPECT_NEAR(a.ape_m.std, 0.0, 1e-12);
  EXPECT_NEAR(a.end_point.error_m, offset, 1e-12);
  EXPECT_NEAR(a.end_point.percent_of_distance, 100.0 * offset / a.gt_distance_m, 1e-9);
  // A world offset does not change relative motion.
  for (const RpeResult& r : a.rpe) {
    EXPECT_NEAR(r.translation_m.max, 0.0, 1e-9);
    EXPECT_NEAR(r.rotation_deg.max, 0.0, 1e-6);
  }

  const EvalResult b = evaluate(gt, est, EvalConfig{});  // default: se3
  ASSERT_TRUE(b.valid);
  EXPECT_FALSE(b.alignment.degenerate);
  EXPECT_LT(b.ape_m.max, 1e-9);
  EXPECT_NEAR((b.alignment.translation + Eigen::Vector3d(0.3, -0.4, 1.2)).norm(), 0.0, 1e-9);
}

TEST(Ape, KnownRotationAboutOrigin) {
  // Points on a circle of radius 10 rotated 30 deg about z: each moves by the chord 2 r sin(15 deg).
  const Trajectory gt = test::circle(120, 10.0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Trajectory est = transformed(gt, R, Eigen::Vector3d::Zero());
  const double chord = 2.0 * 10.0 * std::sin(M_PI / 12);  // 5.1764 m

  EvalConfig none;
  none.align = AlignMode::kNone;
  const EvalResult a = evaluate(gt, est, none);
  EXPECT_NEAR(a.ape_m.rmse, chord, 1e-9);
  EXPECT_NEAR(a.ape_m.min, chord, 1e-9);
  EXPECT_NEAR(a.ape_m.max, chord, 1e-9);

  const EvalResult b = evaluate(gt, est, EvalConfig{});
  EXPECT_LT(b.ape_m.max, 1e-9);
  // The alignment found is the inverse rotation (estimate -> ground truth).
  EXPECT_NEAR((b.alignment.rotation - R.transpose()).norm(), 0.0, 1e-9);
}

TEST(Ape, Sim3RecoversScale) {
  const Trajectory gt = test::windingPath(250);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Trajectory est = transformed(gt, R, Eigen::Vector3d(5, -2, 1), 0.5);

  EvalConfig se3;
  const EvalResult rigid = evaluate(gt, est, se3);
  EXPECT_GT(rigid.ape_m.rmse, 5.0);  // half-size copy cannot be fitted rigidly

  EvalConfig sim3;
  sim3.align = AlignMode::kSim3;
  const EvalResult s = evaluate(gt, est, sim3);
  EXPECT_NEAR(s.alignment.scale, 2.0, 1e-9);
  EXPECT_LT(s.ape_m.max, 1e-8);
  for (const RpeResult& r : s.rpe) EXPECT_LT(r.translation_m.max, 1e-8);
}

TEST(Ape, GaussianNoiseOfKnownRmse) {
  // Per-axis N(0, 0.05^2) noise: expected APE rmse sqrt(3) * 0.05 = 0.0866 m.
  const double sigma = 0.05;
  const Trajectory gt = test::windingPath(3000);
  Trajectory est = gt;
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, sigma);
  double sum_sq = 0.0;
  for (StampedPose& p : est) {
    const Eigen::Vector3d n(noise(rng), noise(rng), noise(rng));
    p.pose.translation() += n;
    sum_sq += n.squaredNorm();
  }
  const double realised_rmse = std::sqrt(sum_sq / 3000.0);

  EvalConfig none;
  none.align = AlignMode::kNone;
  const EvalResult a = evaluate(gt, est, none);
  EXPECT_NEAR(a.ape_m.rmse, realised_rmse, 1e-12);           // exact: same numbers
  EXPECT_NEAR(a.ape_m.rmse, std::sqrt(3.0) * sigma, 0.003);  // statistical: 3000 samples, ~1.3% spread
  // Norm of 3 iid normals is Maxwell distributed: mean 2 sigma sqrt(2/pi) = 0.0798 m.
  EXPECT_NEAR(a.ape_m.mean, 2.0 * sigma * std::sqrt(2.0 / M_PI), 0.003);

  // SE(3) alignment absorbs a little of the noise (6 dof out of 9000 numbers) but not more.
  const EvalResult b = evaluate(gt, est, EvalConfig{});
  EXPECT_LE(b.ape_m.rmse, a.ape_m.rmse + 1e-12);
  EXPECT_GT(b.ape_m.rmse, 0.995 * a.ape_m.rmse);
}

TEST(Rpe, PairsByPathLengthFollowEvo) {
  // 0.25 m steps: the path first reaches 1 m at index 4; pairs (4,8), (8,12), ...
  const Trajectory poses = test::line(41, 0.25);  // indices 0..40
  const auto pairs = pairsByPathLength(poses, 1.0);
  ASSERT_EQ(pairs.size(), 9u);  // ids 4, 8, ..., 40
  EXPECT_EQ(pairs.front(), std::make_pair(std::size_t{4}, std::size_t{8}));
  EXPECT_EQ(pairs.back(), std::make_pair(std::size_t{36}, std::size_t{40}));
  EXPECT_TRUE(pairsByPathLength(poses, 6.0).empty());  // 10 m of path: only one id at 6 m
}

TEST(Rpe, ScaleErrorGivesKnownTranslationError) {
  // Estimate steps 1% too long: every 1 m pair (4 steps) is 1 cm too long; 10 m pairs 10 cm.
  const Trajectory gt = test::line(401, 0.25);
  const Trajectory est = test::line(401, 0.2525);
  const auto pairs = pairsByPathLength(est, 1.0);
  ASSERT_EQ(pairs.size(), 99u);
  const RelativeErrors e = relativeErrors(gt, est, pairs);
  const ErrorStats s = computeStats(e.translation_m);
  EXPECT_NEAR(s.min, 0.01, 1e-9);
  EXPECT_NEAR(s.max, 0.01, 1e-9);
  EXPECT_NEAR(computeStats(e.rotation_deg).max, 0.0, 1e-9);

  const ErrorStats ten = computeStats(relativeErrors(gt, est, pairsByPathLength(est, 10.0)).translation_m);
  EXPECT_NEAR(ten.rmse, 0.1, 1e-9);  // 10 m pairs: ids every 40 steps (10.1 m of estimate)
}

TEST(Rpe, YawDriftGivesKnownRotationError) {
  // Heading drifts 0.5 deg per pose; 1 m pairs span 4 poses -> 2 deg rotation error each.
  const Trajectory gt = test::line(201, 0.25);
  Trajectory est = gt;
  for (std::size_t k = 0; k < est.size(); ++k)
    est[k].pose.linear() = Eigen::AngleAxisd(0.5 * M_PI / 180.0 * k, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const ErrorStats r = computeStats(relativeErrors(gt, est, pairsByPathLength(est, 1.0)).rotation_deg);
  EXPECT_EQ(r.count, 49u);
  EXPECT_NEAR(r.min, 2.0, 1e-9);
  EXPECT_NEAR(r.max, 2.0, 1e-9);
}

TEST(Drift, OnePercentScaleErrorOnAStraightKilometre) {
  // 1 m steps; the devkit's segment for L ends at the first frame with distance > start + L, i.e.
  // L + 1 metres of ground truth, divided by L: translational error 1.01 * 1%.
  const Trajectory gt = test::line(1001, 1.0);
  const Trajectory est = test::line(1001, 1.01);
  const std::vector<double> lengths = {100, 200, 300, 400, 500, 600, 700, 800};
  const KittiDrift d = kittiDrift(gt, est, lengths, 10);
  ASSERT_TRUE(d.available);
  std::size_t expected_segments = 0;
  for (double L : lengths) expected_segments += static_cast<std::size_t>((999 - L) / 10) + 1;
  EXPECT_EQ(d.segments, expected_segments);
  EXPECT_EQ(d.per_length.size(), 8u);
  double expected = 0.0;
  for (const DriftLength& l : d.per_length) {
    EXPECT_NEAR(l.translation_percent, (l.length_m + 1.0) / l.length_m, 1e-9);
    expected += l.translation_percent * static_cast<double>(l.segments);
  }
  EXPECT_NEAR(d.translation_percent, expected / static_cast<double>(expected_segments), 1e-9);
  EXPECT_NEAR(d.rotation_deg_per_m, 0.0, 1e-12);
}

TEST(Drift, RotationDriftInDegreesPerMetre) {
  // Constant 0.001 rad/m of yaw error after the first pose: a 100 m segment (101 frames) errs by
  // 0.101 rad -> 0.101 / 100 rad/m = 0.05787 deg/m.
  const Trajectory gt = test::line(301, 1.0);
  Trajectory est = gt;
  for (std::size_t k = 0; k < est.size(); ++k)
    est[k].pose.linear() = Eigen::AngleAxisd(0.001 * k, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const KittiDrift d = kittiDrift(gt, est, {100.0}, 10);
  ASSERT_TRUE(d.available);
  EXPECT_NEAR(d.rotation_deg_per_m, 0.101 / 100.0 * 180.0 / M_PI, 1e-9);
}

TEST(Drift, NotAvailableOnShortPaths) {
  const Trajectory gt = test::line(90, 1.0);  // 89 m
  EXPECT_FALSE(kittiDrift(gt, gt, {100.0, 200.0}, 10).available);
  const EvalResult r = evaluate(test::windingPath(100), test::windingPath(100));  // ~60 m
  EXPECT_FALSE(r.drift.available);
}

TEST(Evaluate, DistanceTravelledAndEndPoint) {
  const Trajectory gt = test::line(101, 0.5);  // 50 m
  Trajectory est = gt;
  est.back().pose.translation() += Eigen::Vector3d(0, 0.3, 0.4);  // last pose 0.5 m off
  EvalConfig none;
  none.align = AlignMode::kNone;
  const EvalResult r = evaluate(gt, est, none);
  EXPECT_NEAR(r.gt_distance_m, 50.0, 1e-9);
  EXPECT_NEAR(r.duration_s, 10.0, 1e-9);
  EXPECT_NEAR(r.end_point.error_m, 0.5, 1e-12);
  EXPECT_NEAR(r.end_point.percent_of_distance, 1.0, 1e-9);
  // 1 of 101 errors is 0.5: rmse = 0.5 / sqrt(101).
  EXPECT_NEAR(r.ape_m.rmse, 0.5 / std::sqrt(101.0), 1e-12);
}

TEST(Evaluate, DegenerateOrEmptyInputDoesNotCrash) {
  // A straight line: evo refuses SE(3) alignment (rank-1 covariance); we flag it and match centroids.
  const Trajectory gt = test::line(50, 1.0);
  const Trajectory est = transformed(gt, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 2, 0));
  const EvalResult r = evaluate(gt, est);
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.alignment.degenerate);
  EXPECT_FALSE(r.message.empty());
  EXPECT_LT(r.ape_m.max, 1e-9);  // centroid match removes a pure offset

  Trajectory with_nan = est;
  with_nan[7].pose.translation().x() = std::nan("");
  with_nan[9].pose.linear()(0, 0) = INFINITY;
  const EvalResult n = evaluate(gt, with_nan);
  ASSERT_TRUE(n.valid);
  EXPECT_EQ(n.non_finite_dropped, 2u);
  EXPECT_EQ(n.matched_poses, 48u);
  EXPECT_LT(n.ape_m.max, 1e-9);
  EXPECT_NE(n.message.find("2 matched pairs with non-finite poses ignored"), std::string::npos) << n.message;

  EXPECT_FALSE(evaluate({}, gt).valid);
  EXPECT_FALSE(evaluate(gt, {}).valid);
  const EvalResult one = evaluate(Trajectory(gt.begin(), gt.begin() + 1), Trajectory(est.begin(), est.begin() + 1));
  EXPECT_TRUE(one.valid);
  EXPECT_EQ(one.matched_poses, 1u);
  EXPECT_EQ(one.rpe.at(0).translation_m.count, 0u);
}

TEST(EvalConfig, ReadsDottedKeysWithDefaults) {
  const EvalConfig d = evalConfigFrom(adit::Config{});
  EXPECT_DOUBLE_EQ(d.max_time_diff_s, 0.01);
  EXPECT_EQ(d.align, AlignMode::kSE3);
  EXPECT_EQ(d.rpe_deltas_m, (std::vector<double>{1.0, 10.0, 100.0}));
  const EvalConfig c = evalConfigFrom(adit::Config::fromYamlString(
      "eval:\n  align: sim3\n  max_time_diff_s: 0.02\n  rpe_deltas_m: [2, 20]\n  drift_step_frames: 5\n"));
  EXPECT_EQ(c.align, AlignMode::kSim3);
  EXPECT_DOUBLE_EQ(c.max_time_diff_s, 0.02);
  EXPECT_EQ(c.rpe_deltas_m, (std::vector<double>{2.0, 20.0}));
  EXPECT_EQ(c.drift_step_frames, 5);
}

}  // namespace
}  // namespace adit::eval
