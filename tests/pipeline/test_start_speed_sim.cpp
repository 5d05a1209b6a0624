// A log that starts while the vehicle moves (issue 16, item 2): the whole pipeline on the simulator with the
// robot already driving at t = 0 (sim.motion.start_speed), a crawler at 1.5 m/s with its IMU and a road
// vehicle at 15 m/s (1.5 m between sweeps) without one. The odometry has no motion history at the first
// sweeps; the estimate must match the ground truth from the third sweep on: every relative motion between
// consecutive sweeps that ends at the third sweep or later, and the trajectory from the third sweep, aligned
// there.
#include "sim_pipeline.hpp"

#include <gtest/gtest.h>

namespace adit {
namespace {

struct StartErrors {
  double first_pair_m = 0;         // sweeps 0 -> 1 (raw sweeps, no motion history)
  double worst_pair_m = 0, worst_pair_deg = 0;  // consecutive pairs ending at the third sweep or later
  double worst_position_m = 0;     // the trajectory from the third sweep, both aligned at it
  double distance_m = 0;
};

StartErrors startErrors(const test::SimPipelineRun& run) {
  StartErrors e;
  const Trajectory& gt = run.ground_truth;
  const Trajectory& est = run.corrected;
  auto relative = [](const Trajectory& t, std::size_t a, std::size_t b) { return t[a].pose.inverse() * t[b].pose; };
  e.first_pair_m = translationNorm(relative(gt, 0, 1).inverse() * relative(est, 0, 1));
  for (std::size_t i = 2; i < gt.size(); ++i) {
    const Eigen::Isometry3d pair = relative(gt, i - 1, i).inverse() * relative(est, i - 1, i);
    e.worst_pair_m = std::max(e.worst_pair_m, translationNorm(pair));
    e.worst_pair_deg = std::max(e.worst_pair_deg, rotationAngle(pair) * 180.0 / M_PI);
    if (i == 2) continue;
    const Eigen::Vector3d truth = relative(gt, 2, i).translation(), estimate = relative(est, 2, i).translation();
    e.worst_position_m = std::max(e.worst_position_m, (truth - estimate).norm());
    e.distance_m += relative(gt, i - 1, i).translation().norm();
  }
  return e;
}

void print(const char* what, const StartErrors& e) {
  std::printf("%s: first pair %.3f m off; from the third sweep: worst pair %.3f m / %.3f deg, worst position "
              "%.3f m over %.1f m\n", what, e.first_pair_m, e.worst_pair_m, e.worst_pair_deg, e.worst_position_m,
              e.distance_m);
}

TEST(StartSpeedSim, CrawlerAlreadyDrivingWithImu) {
  test::SimPipelineSetup setup;
  setup.adjust = [](sim::SimConfig& c) { c.motion.start_speed = 1.5; };
  const auto run = test::runSimPipeline("roadway-straight", 10.0, 3, setup);
  ASSERT_EQ(run.corrected.size(), run.ground_truth.size());
  const StartErrors e = startErrors(run);
  print("crawler 1.5 m/s, IMU", e);
  // Measured: first pair 0.010 m; from the third sweep worst pair 0.044 m / 0.53 deg (0.14 m per sweep; the
  // 4 cm pairs are the 5th and 7th, the same without IMU, later pairs reach 0.030 m; 0.5 deg is a later pair:
  // the floor's pitch and roll), worst position 0.049 m over 13.5 m. The pair ending at the third sweep erred
  // by 0.065 m while the first two sweeps were deskewed by the IMU's rotation alone (their translation taken
  // as zero, features.deskew.rotation_only_without_prior); left raw and compensated downstream: 0.008 m.
  EXPECT_GT(e.distance_m, 12.0);
  EXPECT_LT(e.first_pair_m, 0.05);
  EXPECT_LT(e.worst_pair_m, 0.05);
  // The worst pair's rotation is the largest of ~100 pairs, driven by the rough floor, and moves with any change
  // to registration: 0.53-0.56 deg before match reuse; with odometry / mapping reuse_match_distance_m of
  // 0 / 0, 0.01, 0.015, 0.02, 0.03 m it was 0.563, 0.556, 0.584, 0.623, 0.555 deg (and 0.651 with 0.02 m in
  // odometry alone). A start-up that went wrong errs by degrees; 0.7 deg leaves that spread room.
  EXPECT_LT(e.worst_pair_deg, 0.7);
  EXPECT_LT(e.worst_position_m, 0.1);
}

TEST(StartSpeedSim, RoadVehicleAt15MetresPerSecondWithoutImu) {
  test::SimPipelineSetup setup;
  setup.imu = false;
  setup.adjust = [](sim::SimConfig& c) {
    c.motion.start_speed = c.motion.cruise_speed = c.motion.max_speed = 15.0;
    // A car on a graded haulage road, not a crawler on a rough floor: wheelbase and track of a car (pitch and
    // roll from the road under the wheels), a sprung body (little vibration), a smoother floor. The crawler's
    // floor and chassis at 15 m/s would pitch and roll the lidar 1-4 deg within each sweep at up to 10 Hz,
    // which nothing without an IMU can deskew.
    c.motion.max_accel = 2.0;  // it brakes for the roadway's end in time
    c.motion.max_decel = 3.0;
    c.motion.track_length = 2.7;
    c.motion.track_width = 1.6;
    c.motion.vibration_deg = 0.02;
    c.motion.bounce = 0.001;
    c.roadway = sim::worldConfigFor(c.world, c.seed);
    c.roadway->floor_roughness = 0.01;
  };
  const auto run = test::runSimPipeline("roadway-straight", 8.0, 3, setup);
  ASSERT_EQ(run.corrected.size(), run.ground_truth.size());
  const StartErrors e = startErrors(run);
  print("road vehicle 15 m/s, no IMU", e);
  // Measured: first pair 0.020 m; from the third sweep worst pair 0.065 m / 2.3 deg, worst position 0.53 m
  // over 112 m (0.5 %). Without the start-up search (odometry.startup_max_speed_mps: 0) the estimate covers
  // 37 of 115 m (APE 22 m). The rotation bound is the pipeline's without an IMU at any speed (Reliability:
  // up to 2.9 deg per sweep): the sweeps are deskewed with the last motion, not the body's pitch and roll.
  EXPECT_GT(e.distance_m, 100.0);
  EXPECT_LT(e.first_pair_m, 0.1);
  EXPECT_LT(e.worst_pair_m, 0.1);
  EXPECT_LT(e.worst_pair_deg, 3.0);
  EXPECT_LT(e.worst_position_m, 0.8);
}

}  // namespace
}  // namespace adit
