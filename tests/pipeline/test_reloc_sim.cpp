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
            const std::string& prior_map, const std::string& mode = "localise") {
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
  options.config.set("reloc.mode", mode);
  if (!prior_map.empty()) options.stages = {"feature", "odometry", "mapper"};
  if (mode == "extend") options.stages.push_back("loop_closer");
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

// Mode extend: the second drive starts 30 m into the first (mapped 0-75 m), drives on to ~130 m, and is saved
// as one bundle of both. Its new keyframes must be where the truth says in the first drive's frame, none may
// lie on the first drive's roadway (mapped once), the roadway length must be that of both drives' union, and a
// third drive put down in the new part must relocalise in the joined bundle.
TEST(RelocaliseSim, ASecondDriveExtendsTheMapWithItsNewRoadwayOnly) {
  const std::string first_bundle = (fs::temp_directory_path() / ("adit_extend_a_" + std::to_string(::getpid()))).string();
  const std::string joined = (fs::temp_directory_path() / ("adit_extend_ab_" + std::to_string(::getpid()))).string();
  const Drive first = drive(60.0, 0.0, "ext_first", first_bundle, "");
  const MapBundle a = loadMapBundle(first_bundle);
  const Drive second = drive(80.0, 30.0, "ext_second", joined, first_bundle, "extend");
  std::printf("%s", second.json.c_str());
  const MapBundle both = loadMapBundle(joined);
  const std::size_t n = a.keyframes.size();
  ASSERT_GT(both.keyframes.size(), n + 30) << "the new roadway (~55 m) was not added";
  // Solved whole, but this run closes no loop through the map: the saved keyframes stay where they were.
  double saved_moved = 0;
  for (std::size_t k = 0; k < n; ++k)
    saved_moved = std::max(saved_moved, (both.keyframes[k].pose.translation() - a.keyframes[k].pose.translation()).norm());
  EXPECT_LT(saved_moved, 0.05);

  const Eigen::Isometry3d T_world_map = first.ground_truth.front().pose * first.estimate.front().pose.inverse();
  std::map<std::int64_t, Eigen::Isometry3d> truth;
  for (const StampedPose& p : second.ground_truth) truth[p.utime] = p.pose;
  double sum_sq = 0, worst = 0, worst_deg = 0, nearest_first = 1e9;
  std::vector<double> errors;
  for (std::size_t k = n; k < both.keyframes.size(); ++k) {
    ASSERT_TRUE(truth.count(both.keyframes[k].utime));
    const Eigen::Isometry3d& true_pose = truth[both.keyframes[k].utime];
    const Eigen::Isometry3d error = true_pose.inverse() * T_world_map * both.keyframes[k].pose;
    sum_sq += translationNorm(error) * translationNorm(error);
    errors.push_back(translationNorm(error));
    worst = std::max(worst, translationNorm(error));
    worst_deg = std::max(worst_deg, rotationAngle(error) * 180.0 / M_PI);
    for (const StampedPose& p : first.ground_truth)
      nearest_first = std::min(nearest_first, (p.pose.translation() - true_pose.translation()).norm());
  }
  const double rmse = std::sqrt(sum_sq / static_cast<double>(both.keyframes.size() - n));
  // The distinct roadway of both drives, from the truth: the union of their paths.
  std::vector<Eigen::Vector3d> first_path, second_path;
  for (const StampedPose& p : first.ground_truth) first_path.push_back(p.pose.translation());
  for (const StampedPose& p : second.ground_truth) second_path.push_back(p.pose.translation());
  const double true_union = roadwayLength(first_path, 3.0, 30) + roadwayLength(second_path, 3.0, 30, first_path);
  // The map's own error where the new roadway begins: the first drive's estimate at its end.
  const double map_end_error = translationNorm(first.ground_truth.back().pose.inverse() * T_world_map * first.estimate.back().pose);
  std::printf("new keyframes' error from the junction on:");
  for (std::size_t k = 0; k < errors.size(); k += 6) std::printf(" %.3f", errors[k]);
  std::printf(" m; the first drive's own error at its end %.3f m\n", map_end_error);
  std::printf("extended: %zu + %zu keyframes; new ones: APE RMSE %.3f m, worst %.3f m / %.2f deg, nearest to the first "
              "drive's path %.2f m; roadway %.1f m (%.1f + new), truth %.1f m\n", n, both.keyframes.size() - n, rmse,
              worst, worst_deg, nearest_first, both.summary.roadway_length_m, a.summary.roadway_length_m, true_union);
  // Measured (2026-11-28): 49 of 91 keyframes added, RMSE 0.202 m, worst 0.265 m / 0.83 deg, saved keyframes
  // moved <= 0.01 m. The new roadway starts where the map is (0.153 m from the truth where the map itself is
  // 0.155 m off at its end: the first drive's own drift over 75 m) and drifts 0.11 m more over 52 m of odometry
  // with nothing to close on.
  EXPECT_LE(std::abs(errors.front() - map_end_error), 0.1) << "the new roadway does not continue the map";
  EXPECT_LE(worst - map_end_error, 0.25);
  EXPECT_LE(rmse, 0.3);
  EXPECT_LE(worst_deg, 2.0);
  // Mapped once: no new keyframe on the first drive's roadway (the overlap radius is 2 m; a keyframe 1 m apart).
  EXPECT_GT(nearest_first, 1.0);
  EXPECT_NEAR(both.summary.roadway_length_m, true_union, 0.1 * true_union);

  // The joined bundle is a product: a drive put down in its new part (110 m) relocalises there.
  const Drive third = drive(20.0, 110.0, "ext_third", "", joined);
  std::printf("%s", third.json.c_str());
  ASSERT_FALSE(third.in_map.empty()) << "no fix in the new part of the joined map";
  std::map<std::int64_t, Eigen::Isometry3d> third_truth;
  for (const StampedPose& p : third.ground_truth) third_truth[p.utime] = p.pose;
  double third_worst = 0;
  for (const StampedPose& p : third.in_map)
    third_worst = std::max(third_worst, translationNorm(third_truth[p.utime].inverse() * T_world_map * p.pose));
  std::printf("third drive: first fix after %.1f s, worst %.3f m\n",
              static_cast<double>(third.in_map.front().utime - third.ground_truth.front().utime) * 1e-6, third_worst);
  // Measured: first fix after 7.0 s, worst 0.274 m (the joined map's own error there, see above).
  EXPECT_LE(third_worst, 0.4);
  for (const std::string& dir : {first.out_dir, second.out_dir, third.out_dir, first_bundle, joined}) fs::remove_all(dir);
}

}  // namespace
}  // namespace adit
