// A featureless roadway with wheel odometry (issue 16, item 3): the whole pipeline (the nodes of adit replay,
// in lockstep) on the simulator's featureless world, a smooth arched tunnel whose axis the lidar cannot
// observe once both dead ends are out of range. The simulator publishes WHEEL_ODOM with 3-8 % slip and
// noise; the odometry calibrates the slip while the near dead end is in view and then holds the degenerate
// axis to the wheel. The feature stage's range is cut to 30 m so that the degenerate zone starts ~30 m in
// (the same geometry as the 1 km run of scripts/featureless_km.sh at a fraction of the time).
// And the other side of the same change: where the roadway is structured nothing may get worse.
#include "eval/evaluate.hpp"
#include "sim_pipeline.hpp"

#include <gtest/gtest.h>

namespace adit {
namespace {

struct EndError {
  double distance_m = 0, end_error_m = 0, axial_error_m = 0;
};

// Both trajectories from their first pose: the distance driven and the error at the last sweep.
EndError endError(const Trajectory& gt, const Trajectory& est) {
  EndError e;
  const std::size_t n = std::min(gt.size(), est.size());
  for (std::size_t i = 1; i < n; ++i) e.distance_m += (gt[i].pose.translation() - gt[i - 1].pose.translation()).norm();
  const Eigen::Isometry3d truth = gt.front().pose.inverse() * gt[n - 1].pose;
  const Eigen::Isometry3d estimate = est.front().pose.inverse() * est[n - 1].pose;
  e.end_error_m = (truth.translation() - estimate.translation()).norm();
  e.axial_error_m = estimate.translation().x() - truth.translation().x();
  return e;
}

TEST(FeaturelessSim, WheelOdometryCarriesTheUnobservedAxis) {
  test::SimPipelineSetup setup;
  setup.adjust = [](sim::SimConfig& c) { c.wheel.enabled = true; };
  setup.configure = [](Config& c) { c.set("features.preprocess.max_range", "30"); };
  // 60 s: 2 s standing, ~28 m with the near dead end in range (slip calibrated), then ~45 m without.
  const auto run = test::runSimPipeline("featureless", 60.0, 1, setup);
  ASSERT_EQ(run.corrected.size(), run.ground_truth.size());
  const EndError e = endError(run.ground_truth, run.corrected);
  const auto counter = [&](const char* name) {
    const auto it = run.odometry_counters.find(name);
    return it == run.odometry_counters.end() ? std::int64_t{0} : it->second;
  };
  std::printf("featureless 60 s with wheel odometry: %.1f m driven, end-point error %.3f m (%.2f %%, axial %+.3f m); "
              "degenerate sweeps %lld, held to the wheel %lld, calibrations %lld, scale %.4f, stuck %lld, "
              "disagreements %lld\n",
              e.distance_m, e.end_error_m, 100.0 * e.end_error_m / e.distance_m, e.axial_error_m,
              static_cast<long long>(counter("degenerate_translation")), static_cast<long long>(counter("held_to_wheel")),
              static_cast<long long>(counter("wheel_calibrations")), 1e-6 * static_cast<double>(counter("wheel_scale_ppm")),
              static_cast<long long>(counter("wheel_stuck")), static_cast<long long>(counter("wheel_disagrees")));
  EXPECT_GT(e.distance_m, 65.0);
  EXPECT_GT(counter("held_to_wheel"), 200);  // the zone was degenerate and the wheel carried it
  EXPECT_GT(counter("wheel_calibrations"), 50);  // 76: sweeps that observe the axis well are few here
  EXPECT_EQ(counter("wheel_stuck"), 0);       // a noisy, moving encoder is never frozen
  EXPECT_GT(counter("degenerate_along_x"), 200);  // the roadway's axis, whatever held it
  // Measured 0.77 % (0.56 m short; lidar + IMU alone on the same run: 1.38 %), with edge lines through every
  // ring that sees the edge (odometry.line_through_all_rings); with two-point lines 1.27 % (lidar + IMU
  // 5.31 %). What is left is the slip calibration against scan-to-scan odometry (scale 0.924, truth 0.938).
  EXPECT_LT(e.end_error_m, 0.02 * e.distance_m);
}

// The velocity degenerate directions hold to is averaged with each sweep weighted by how well it observed
// each direction. Weighted by the planes alone, roadway-loop's axis (pinned by arches and equipment, i.e.
// edges) counted as barely observed, the held speed lagged the robot's accelerations and the 20 s run lost
// accuracy (APE 0.0111 -> 0.0204 m); weighted by all residuals it must do as well as the plain average. One
// 20 s drive's APE (~1 cm) moves by a per cent with any change of the odometry (seed 4 alone: +1.2 % with
// edge lines through every ring), so the claim is made over three drives.
TEST(FeaturelessSim, StructuredRoadwayLosesNothingToTheObservedWeighting) {
  const auto ape = [](const char* ratio, std::uint64_t seed) {
    test::SimPipelineSetup setup;
    setup.configure = [ratio](Config& c) { c.set("odometry.hold_velocity_observed_ratio", ratio); };
    const auto run = test::runSimPipeline("roadway-loop", 20.0, seed, setup);
    const eval::EvalResult r = eval::evaluate(run.ground_truth, run.corrected);
    EXPECT_TRUE(r.valid) << r.message;
    return r.ape_m.rmse;
  };
  double unweighted = 0, weighted = 0;
  for (const std::uint64_t seed : {4, 5, 6}) {
    const double u = ape("0", seed), w = ape("0.1", seed);
    std::printf("roadway-loop 20 s seed %llu: APE %.4f m unweighted, %.4f m weighted by what was observed\n",
                static_cast<unsigned long long>(seed), u, w);
    unweighted += u;
    weighted += w;
  }
  std::printf("mean over 3 drives: %.4f m unweighted, %.4f m weighted (%+.1f %%)\n", unweighted / 3, weighted / 3,
              100.0 * (weighted / unweighted - 1.0));
  EXPECT_LE(weighted, 1.01 * unweighted);
}

}  // namespace
}  // namespace adit
