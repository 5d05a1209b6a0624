// adit replay <log> -o <out_dir> [--config FILE]
#include "commands.hpp"

#include "pipeline/replay.hpp"
#include "runtime/process.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdio>

namespace {

struct ReplayArgs {
  std::string log, out_dir;
  std::vector<std::string> configs;
  std::vector<std::string> stages;
  std::string record = ".*";
  bool no_progress = false;
};

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
  cmd->add_option("--record", args->record, "Regex of the channels written to output.lcmlog (default: all)");
  cmd->add_flag("--no-progress", args->no_progress, "No progress bar even on a terminal");
  cmd->callback([args] {
    adit::pipeline::ReplayOptions options;
    options.input_log = args->log;
    options.out_dir = args->out_dir;
    options.config = adit::runtime::loadConfig(args->configs);
    options.stages = args->stages;
    options.record = args->record;
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
