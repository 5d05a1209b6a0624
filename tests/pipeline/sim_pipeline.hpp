// Runs the whole pipeline (the nodes of `adit replay`, in lockstep) on the simulator and collects what the
// tests judge: ground truth, trajectories before and after loop closure, and the loops with their true error.
#pragma once

#include "core/geometry.hpp"
#include "eval/loop_recall.hpp"
#include "eval/trajectory_io.hpp"
#include "loop/loop_closer.hpp"
#include "msg/convert.hpp"
#include "pipeline/replay.hpp"
#include "runtime/lcm_log.hpp"
#include "runtime/process.hpp"
#include "sources/sim_source.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <string>

namespace adit::test {

struct SimPipelineRun {
  Trajectory ground_truth, odometry, corrected;
  Trajectory scan_odometry;  // ODOM_SCAN: scan-to-scan odometry alone (SimPipelineSetup::scan_odometry)
  std::map<std::string, std::int64_t> odometry_counters;  // the odometry stage's STATUS counters at the end
  std::map<std::string, std::int64_t> loop_counters;      // the loop closer's
  std::vector<LoopConstraint> loops;
  std::vector<eval::JudgedLoop> judged_loops;  // the same loops, each judged against the truth
  int false_loops = 0;
  double worst_loop_error_m = 0, worst_loop_error_deg = 0;
};

// A loop is false when its relative pose is far from the true one: a different place, not a small misfit.
constexpr double kFalseLoopMetres = 1.0;
constexpr double kFalseLoopDegrees = 5.0;

// What a test changes beyond world, duration and seed.
struct SimPipelineSetup {
  std::function<void(sim::SimConfig&)> adjust;  // e.g. motion.start_speed
  bool imu = true;                              // false: the simulator publishes no IMU
  bool scan_odometry = false;                   // also collect ODOM_SCAN's poses (SimPipelineRun::scan_odometry)
  std::function<void(Config&)> configure;       // pipeline keys beyond launch/config + launch/sensors/sim.yaml
};

inline SimPipelineRun runSimPipeline(const std::string& world, double duration_s, std::uint64_t seed,
                                     const SimPipelineSetup& setup = {}) {
  namespace fs = std::filesystem;
  const fs::path launch = fs::path(ADIT_SOURCE_DIR) / "launch";
  Config config = runtime::loadConfig(
      {(launch / "config" / "pipeline.yaml").string(), (launch / "sensors" / "sim.yaml").string()});
  if (setup.configure) setup.configure(config);
  sim::SimConfig sim = sim::simConfigFrom(config, world, seed);
  sim.duration_s = duration_s;
  if (setup.adjust) setup.adjust(sim);
  sources::SimChannels channels;
  if (!setup.imu) channels.imu.clear();
  sources::SimSource source(sim, channels);

  pipeline::ReplayOptions options;
  options.source = &source;
  static int runs = 0;  // several runs in one test process
  options.out_dir = (fs::temp_directory_path() /
                     ("adit_pipeline_" + world + "_" + std::to_string(::getpid()) + "_" + std::to_string(runs++)))
                        .string();
  options.config = config;
  options.record = "^LOOP_CLOSURE$";
  if (setup.scan_odometry) options.record_poses = "^ODOM_SCAN$";
  const pipeline::ReplayReport report = pipeline::runReplay(options);

  SimPipelineRun run;
  for (const auto& stage : report.timing)
    if (stage.stage == "odometry") run.odometry_counters = stage.counters;
    else if (stage.stage == "loop_closer") run.loop_counters = stage.counters;
  run.ground_truth = source.groundTruth();
  run.odometry = eval::readTum(options.out_dir + "/odometry.tum");
  run.corrected = eval::readTum(options.out_dir + "/trajectory.tum");
  runtime::LogReader log(options.out_dir + "/output.lcmlog");
  runtime::LogEvent e;
  while (log.next(e)) {
    adit::odometry_t scan;
    if (e.channel == "ODOM_SCAN" && scan.decode(e.data.data(), 0, static_cast<int>(e.data.size())) >= 0) {
      const PoseEstimate pose = msg::fromMessage(scan);
      run.scan_odometry.push_back({pose.utime, pose.pose});
      continue;
    }
    adit::loop_closure_t m;
    if (e.channel != "LOOP_CLOSURE" || m.decode(e.data.data(), 0, static_cast<int>(e.data.size())) < 0) continue;
    const LoopConstraint loop = msg::fromMessage(m);
    run.loops.push_back(loop);
    const auto& truth_of = source.simulator();
    const Eigen::Isometry3d truth =
        truth_of.groundTruth(loop.match_utime).pose.inverse() * truth_of.groundTruth(loop.query_utime).pose;
    const Eigen::Isometry3d error = truth.inverse() * loop.T_match_query;
    // A partial loop (loop.partial_loops) leaves one axis to the odometry: what ICP slid to along it is no error.
    const double metres = measuredPart(loop, error.translation()).norm(), degrees = rotationAngle(error) * 180.0 / M_PI;
    run.worst_loop_error_m = std::max(run.worst_loop_error_m, metres);
    run.worst_loop_error_deg = std::max(run.worst_loop_error_deg, degrees);
    const bool wrong = metres > kFalseLoopMetres || degrees > kFalseLoopDegrees;
    if (wrong) ++run.false_loops;
    if (wrong)  // what a wrong loop looked like to the verifier, for whoever has to find out why it passed
      std::fprintf(stderr, "false loop: query %.1f s -> match %.1f s, %.2f m / %.2f deg off the truth (ICP rms %.3f m, inliers %.2f, Scan Context %.3f)\n",
                   toSeconds(loop.query_utime), toSeconds(loop.match_utime), metres, degrees, loop.fitness,
                   loop.inlier_ratio, loop.scan_context_distance);
    run.judged_loops.push_back({loop.query_utime, !wrong});
  }
  fs::remove_all(options.out_dir);
  return run;
}

}  // namespace adit::test
