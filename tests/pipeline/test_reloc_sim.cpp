// Relocalisation on a saved map (issue 18), whole pipeline on the simulator: a first drive through
// roadway-loop is mapped and saved as a bundle; a second drive of the same roadway starts 30 m into the first,
// with no initial guess. It must relocalise, publish no pose in the map frame before that, and its poses in the
// map must match its ground truth expressed in the first drive's frame (the first drive's estimate anchored to
// its ground truth at its first sweep): APE <= 0.2 m.
#include "core/geometry.hpp"
#include "eval/trajectory_io.hpp"
#include "map/map_bundle.hpp"
#include "pipeline/replay.hpp"
#include "runtime/process.hpp"
#include "sources/sim_source.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace adit {
namespace {
namespace fs = std::filesystem;

struct Drive {
  Trajectory ground_truth, estimate, in_map;
  std::string out_dir, json;
};

Drive drive(double duration_s, double start_distance, const std::string& name, const std::string& save_bundle,
            const std::string& prior_map) {
  const fs::path launch = fs::path(ADIT_SOURCE_DIR) / "launch";
  const Config config = runtime::loadConfig(
      {(launch / "config" / "pipeline.yaml").string(), (launch / "sensors" / "sim.yaml").string()});
  sim::SimConfig sim = sim::simConfigFrom(config, "roadway-loop", 1);
  sim.duration_s = duration_s;
  sim.motion.start_distance = start_distance;
  sources::SimSource source(sim, sources::SimChannels{});
  pipeline::ReplayOptions options;
  options.source = &source;
  options.out_dir = (fs::temp_directory_path() / ("adit_reloc_" + name + "_" + std::to_string(::getpid()))).string();
  options.config = config;
  options.record = "^POSE_IN_MAP$";
  options.save_bundle = save_bundle;
  options.prior_map = prior_map;
  if (!prior_map.empty()) options.stages = {"feature", "odometry", "mapper"};
  pipeline::runReplay(options);
  Drive d;
  d.ground_truth = source.groundTruth();
  d.estimate = eval::readTum(options.out_dir + "/trajectory.tum");
  d.out_dir = options.out_dir;
  if (!prior_map.empty()) {
    d.in_map = eval::readTum(options.out_dir + "/map_trajectory.tum");
    std::ifstream in(options.out_dir + "/relocalisation.json");
    std::stringstream s;
    s << in.rdbuf();
    d.json = s.str();
  }
  return d;
}

TEST(RelocaliseSim, SecondDriveStartingThirtyMetresInRelocalisesWithinTwentyCentimetres) {
  const std::string bundle = (fs::temp_directory_path() / ("adit_reloc_bundle_" + std::to_string(::getpid()))).string();
  const Drive first = drive(60.0, 0.0, "first", bundle, "");
  const MapBundle saved = loadMapBundle(bundle);
  EXPECT_GT(saved.summary.keyframes, 50);
  EXPECT_GT(saved.summary.roadway_length_m, 60.0);

  const Drive second = drive(25.0, 30.0, "second", "", bundle);
  std::printf("%s", second.json.c_str());
  EXPECT_NE(second.json.find("\"state\": \"localised\""), std::string::npos);
  ASSERT_GT(second.in_map.size(), 150u) << "relocalised too late (after 10 s of 25 s) or never";

  // The map frame is the first drive's estimate frame; its ground truth frame is anchored at the first sweep.
  const Eigen::Isometry3d T_world_map = first.ground_truth.front().pose * first.estimate.front().pose.inverse();
  std::map<std::int64_t, Eigen::Isometry3d> truth;
  for (const StampedPose& p : second.ground_truth) truth[p.utime] = p.pose;
  double sum_sq = 0, worst = 0, worst_deg = 0;
  for (const StampedPose& p : second.in_map) {
    ASSERT_TRUE(truth.count(p.utime));
    const Eigen::Isometry3d error = truth[p.utime].inverse() * T_world_map * p.pose;
    sum_sq += translationNorm(error) * translationNorm(error);
    worst = std::max(worst, translationNorm(error));
    worst_deg = std::max(worst_deg, rotationAngle(error) * 180.0 / M_PI);
  }
  const double rmse = std::sqrt(sum_sq / static_cast<double>(second.in_map.size()));
  const double fix_s = static_cast<double>(second.in_map.front().utime - second.ground_truth.front().utime) * 1e-6;
  std::printf("first fix after %.1f s; %zu poses in the map: APE RMSE %.3f m, worst %.3f m / %.2f deg\n", fix_s,
              second.in_map.size(), rmse, worst, worst_deg);
  // Measured: first fix after 6.7 s (8.7 s before the search along the roadway; on this stretch the search
  // finds other places along the line nearly as good for the first seconds and refuses), APE RMSE 0.093 m,
  // worst 0.144 m / 0.59 deg (0.113 m, 0.165 m / 0.96 deg before).
  EXPECT_LE(rmse, 0.2);
  EXPECT_LE(worst, 0.3);
  EXPECT_LE(worst_deg, 2.0);
  for (const std::string& dir : {first.out_dir, second.out_dir, bundle}) fs::remove_all(dir);
}

}  // namespace
}  // namespace adit
