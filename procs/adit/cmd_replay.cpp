// adit replay <log> -o <out_dir> [--config FILE] [--record REGEX | --record-all] [--save-bundle DIR]
//             [--prior-map BUNDLE [--extend] [--start-pose X Y Z HEADING_DEG]]
#include "commands.hpp"

#include "map/map_bundle.hpp"
#include "nodes/registry.hpp"
#include "pipeline/replay.hpp"
#include "runtime/process.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace {

struct ReplayArgs {
  std::string log, out_dir;
  std::vector<std::string> configs;
  std::vector<std::string> stages;
  // The products by default: loop events, the pose graph, STATUS and ground truth whole, and the odometry
  // channels as poses only (a few MB for a 700 s run instead of 8 GB).
  std::string record = "^(LOOP_CLOSURE|POSE_GRAPH|STATUS_.*|GROUND_TRUTH)$";
  std::string record_poses = "^(ODOM_SCAN|ODOM_MAPPED)$";
  bool record_all = false;
  bool no_progress = false;
  bool serial = false;
  std::string save_bundle;
  std::string prior_map;
  bool extend = false;
  std::vector<double> start_pose;
};

// A bundle the run cannot use is an error before anything runs, naming what is wrong. Localising keeps the
// bundle fixed: without --stages the loop closer (whose keyframes grow with the run) is left out; extending
// needs it (its map is what joins the bundle).
void checkPriorMap(const std::string& dir, bool extend, adit::pipeline::ReplayOptions& options) {
  try {
    const adit::BundleSummary summary = adit::readBundleSummary(dir);
    const std::string mismatch = adit::bundleSensorMismatch(summary, adit::nodes::pipelineConfigKeys(options.config));
    if (!mismatch.empty()) throw adit::BundleError(mismatch);
  } catch (const adit::BundleError& e) {
    throw std::runtime_error("--prior-map " + dir + " cannot be used: " + e.what());
  }
  if (options.stages.empty()) options.stages = {"feature", "odometry", "mapper"};
  if (extend && std::find(options.stages.begin(), options.stages.end(), "loop_closer") == options.stages.end())
    options.stages.push_back("loop_closer");
}

}  // namespace

void registerReplayCommand(CLI::App& app) {
  auto args = std::make_shared<ReplayArgs>();
  auto* cmd = app.add_subcommand("replay", "Run the pipeline over an LCM log in one process, in lockstep, as fast as possible");
  cmd->add_option("log", args->log, "Input LCM log (LIDAR_POINTS, IMU)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--out", args->out_dir, "Output folder (output.lcmlog, trajectory.tum, odometry.tum, map.pcd, timing.json)")
      ->required();
  cmd->add_option("--config", args->configs,
                  "YAML configuration, repeatable, later files override (default: built-in defaults, listed in "
                  "launch/config/pipeline.yaml)");
  cmd->add_option("--stages", args->stages, "Only these stages (feature odometry mapper loop_closer)");
  auto* record = cmd->add_option("--record", args->record,
                                 "Regex of the channels written whole to output.lcmlog (default: the products: "
                                 "LOOP_CLOSURE, POSE_GRAPH, STATUS_*, GROUND_TRUTH whole; ODOM_SCAN and ODOM_MAPPED as "
                                 "poses without points)");
  cmd->add_flag("--record-all", args->record_all, "Write every channel whole to output.lcmlog (every stage message)")
      ->excludes(record);
  cmd->add_option("--save-bundle", args->save_bundle,
                  "Also save the run as a map bundle folder (map, keyframes, pose graph, configuration, manifest) "
                  "that later runs can relocalise in (--prior-map)");
  cmd->add_option("--prior-map", args->prior_map,
                  "Start in this map bundle with no initial guess: relocalise (Scan Context + ICP), then publish the "
                  "pose in its frame (POSE_IN_MAP, map_trajectory.tum, relocalisation.json). Mode reloc.mode "
                  "(localise: the bundle stays fixed; the loop closer is not run unless --stages names it)");
  cmd->add_flag("--extend", args->extend,
                "With --prior-map and --save-bundle (reloc.mode extend): the saved bundle is the prior map joined with "
                "this run's new roadway (roadway both hold is kept once, from the prior map)");
  cmd->add_option("--start-pose", args->start_pose,
                  "With --prior-map: the run starts near this pose of the bundle (X Y Z in m, HEADING in deg; "
                  "reloc.start.*): relocalise only within reloc.start.radius of it")
      ->expected(4);
  cmd->add_flag("--no-progress", args->no_progress, "No progress bar even on a terminal");
  cmd->add_flag("--serial", args->serial,
                "Every stage on one thread (default: feature stage and odometry beside mapper and loop closer; the "
                "same output byte for byte)");
  cmd->callback([args] {
    adit::pipeline::ReplayOptions options;
    options.input_log = args->log;
    options.out_dir = args->out_dir;
    options.config = adit::runtime::loadConfig(args->configs);
    options.stages = args->stages;
    options.save_bundle = args->save_bundle;
    options.prior_map = args->prior_map;
    options.pipelined = !args->serial;
    if (args->extend) {
      if (args->prior_map.empty() || args->save_bundle.empty())
        throw CLI::ValidationError("--extend", "needs --prior-map (the map to extend) and --save-bundle (where both go)");
      options.config.set("reloc.mode", "extend");
    }
    if (!args->start_pose.empty()) {
      if (args->prior_map.empty()) throw CLI::ValidationError("--start-pose", "needs --prior-map (the map the pose is in)");
      options.config.set("reloc.start.given", "true");
      const char* keys[] = {"reloc.start.x", "reloc.start.y", "reloc.start.z", "reloc.start.heading_deg"};
      for (int i = 0; i < 4; ++i) options.config.set(keys[i], fmt::format("{}", args->start_pose[static_cast<std::size_t>(i)]));
    }
    if (!args->prior_map.empty()) checkPriorMap(args->prior_map, args->extend, options);
    options.record = args->record_all ? ".*" : args->record;
    options.record_poses = args->record_all ? "" : args->record_poses;
    if (!args->no_progress && ::isatty(STDERR_FILENO)) options.on_progress = drawProgress;
    adit::runtime::installStopHandlers();
    const auto r = adit::pipeline::runReplay(options);
    fmt::print("replayed {} input messages ({:.1f} s of sensor time) in {:.2f} s with stages [{}]: {} messages out, {} "
               "skipped or bad, peak memory {:.0f} MB\n",
               r.input_events, r.sensor_seconds, r.wall_seconds, fmt::join(r.stages_run, ", "), r.output_events,
               r.stage_errors, r.peak_memory_mb);
    for (const auto& t : r.timing)
      fmt::print("  {:<12} {:>6} calls  median {:.2f} ms  p95 {:.2f} ms  max {:.2f} ms\n", t.stage, t.calls, t.median_ms,
                 t.p95_ms, t.max_ms);
    for (const auto& p : r.products) fmt::print("  wrote {}\n", p);
    if (r.corrupt_frames || r.truncated) {  // outputs stay: they are what the readable part gives
      spdlog::error("input log '{}' is damaged: {} corrupt frame(s) skipped{}; the outputs cover its readable part",
                    args->log, r.corrupt_frames, r.truncated ? ", truncated at the end" : "");
      throw CLI::RuntimeError(kExitDamagedInput);
    }
  });
}
