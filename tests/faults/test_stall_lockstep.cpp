// A 10 s lidar outage in lockstep (the nodes of `adit replay` on the simulator): the mapped trajectory goes
// on across the gap from where it was. Before, the odometry restarted at the identity on the time jump and
// the mapper followed it: a 21.9 m jump on this run. The live version through processes is sensor_stall.sh.
#include "core/geometry.hpp"
#include "eval/trajectory_io.hpp"
#include "pipeline/replay.hpp"
#include "runtime/process.hpp"
#include "sources/sim_source.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <map>

namespace fs = std::filesystem;

TEST(SensorStall, MappedTrajectoryDoesNotJumpAcrossALidarGap) {
  const fs::path launch = fs::path(ADIT_SOURCE_DIR) / "launch";
  const adit::Config config = adit::runtime::loadConfig({(launch / "config" / "pipeline.yaml").string()});
  adit::sim::SimConfig sim = adit::sim::simConfigFrom(config, "roadway-straight", 1);
  sim.duration_s = 35;
  adit::sources::SimStalls stalls;
  stalls.lidar = {12.0, 10.0};
  adit::sources::SimSource source(sim, {}, stalls);

  adit::pipeline::ReplayOptions options;
  options.source = &source;
  options.out_dir = (fs::temp_directory_path() / ("adit_stall_" + std::to_string(::getpid()))).string();
  options.config = config;
  options.stages = {"feature", "odometry", "mapper"};
  options.record = "^$";
  adit::pipeline::runReplay(options);
  const adit::Trajectory est = adit::eval::readTum(options.out_dir + "/trajectory.tum");
  fs::remove_all(options.out_dir);

  std::map<std::int64_t, Eigen::Isometry3d> truth;
  for (const auto& p : source.groundTruth()) truth[p.utime] = p.pose;
  ASSERT_EQ(est.size(), truth.size());  // 350 sweeps simulated, 100 of them never sent
  ASSERT_EQ(est.size(), 250u);
  double worst_m = 0, gap_s = 0, error_across_gap_m = 0;
  for (std::size_t i = 1; i < est.size(); ++i) {
    const Eigen::Isometry3d d_est = est[i - 1].pose.inverse() * est[i].pose;
    const Eigen::Isometry3d d_true = truth.at(est[i - 1].utime).inverse() * truth.at(est[i].utime);
    const double m = adit::translationNorm(d_true.inverse() * d_est);
    worst_m = std::max(worst_m, m);
    const double dt = static_cast<double>(est[i].utime - est[i - 1].utime) * 1e-6;
    if (dt > gap_s) gap_s = dt, error_across_gap_m = m;
  }
  EXPECT_NEAR(gap_s, 10.1, 0.05);
  EXPECT_LT(error_across_gap_m, 0.3) << "motion across the gap misestimated";
  EXPECT_LT(worst_m, 0.3);
  std::printf("10 s lidar gap: motion across it off by %.3f m; largest error of a consecutive pair %.3f m\n",
              error_across_gap_m, worst_m);
}
