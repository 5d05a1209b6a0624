// adit demo: the simulated roadway demo. Simulates a robot driving 1.2 laps of a 510 m roadway loop,
// runs the whole pipeline on it in lockstep (no intermediate log), evaluates the result against the
// simulator's ground truth, plots it, and prints a short report.
#include "commands.hpp"

#include "eval/map_accuracy.hpp"
#include "eval/plot.hpp"
#include "io/pcd.hpp"
#include "eval/trajectory_io.hpp"
#include "pipeline/run_summary.hpp"
#include "runtime/process.hpp"
#include "sources/sim_source.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace {

struct DemoArgs {
  std::string world = "roadway-loop", sensor = "vlp16", out_dir;
  std::vector<std::string> configs;
  double duration_s = 500;  // 1.2 laps of roadway-loop at the simulator's 1.3 m/s cruise
  std::int64_t seed = 1;
};

}  // namespace

void registerDemoCommand(CLI::App& app) {
  auto a = std::make_shared<DemoArgs>();
  auto* cmd = app.add_subcommand("demo", "Simulate a roadway, map it, and report the error against ground truth");
  cmd->add_option("--world", a->world, "Simulated world (default roadway-loop)")
      ->check(CLI::IsMember({"roadway-straight", "roadway-loop", "room-and-pillar", "featureless"}));
  cmd->add_option("--sensor", a->sensor, "vlp16 | rs16 | hdl64")->check(CLI::IsMember({"vlp16", "rs16", "hdl64"}));
  cmd->add_option("--duration", a->duration_s, "Simulated seconds (default 500: 1.2 laps of the loop)")->check(CLI::PositiveNumber);
  cmd->add_option("--seed", a->seed, "Seed of the world, motion and noise")->check(CLI::NonNegativeNumber);
  cmd->add_option("--config", a->configs, "Pipeline / simulator YAML (repeatable; default launch/config/pipeline.yaml + launch/sensors/sim.yaml)");
  cmd->add_option("-o,--out", a->out_dir, "Output folder (default <adit>/logs/demo)");
  cmd->callback([a] {
    const fs::path root = fs::weakly_canonical(fs::path(executableDir()) / ".." / "..");
    std::vector<std::string> configs = a->configs;
    if (configs.empty())
      for (const char* f : {"launch/config/pipeline.yaml", "launch/sensors/sim.yaml"})
        if (fs::exists(root / f)) configs.push_back((root / f).string());
    const adit::Config config = adit::runtime::loadConfig(configs);
    const fs::path out = a->out_dir.empty() ? root / "logs" / "demo" : fs::path(a->out_dir);
    fs::create_directories(out);

    adit::sim::SimConfig sim = adit::sim::simConfigFrom(config, a->world, static_cast<std::uint64_t>(a->seed));
    sim.sensor = a->sensor;
    sim.duration_s = a->duration_s;
    adit::sources::SimSource source(sim, {});
    fmt::print("demo: {} ({:.0f} m route), {}, {:.0f} s simulated, seed {}; pipeline config: {}\n", sim.world,
               source.simulator().lapLength(), sim.sensor, sim.duration_s, sim.seed,
               configs.empty() ? "built-in defaults" : fmt::format("{}", fmt::join(configs, " + ")));

    adit::pipeline::ReplayOptions options;
    options.source = &source;
    options.out_dir = out.string();
    options.config = config;
    options.record = "^(ODOM_MAPPED|LOOP_CLOSURE|POSE_GRAPH)$";  // the full sweeps would be gigabytes
    if (::isatty(STDERR_FILENO)) options.on_progress = drawProgress;
    adit::runtime::installStopHandlers();
    const auto replay = adit::pipeline::runReplay(options);

    const std::string gt_path = (out / "ground_truth.tum").string();
    adit::eval::writeTum(gt_path, source.groundTruth());
    auto summary = adit::pipeline::summarizeRun(replay, out.string(), source.groundTruth());
    if (summary.final_eval.valid && fs::exists(out / "map.pcd")) {
      // The saved map against the simulator's surfaces (sampled every 0.1 m), placed by the APE's alignment.
      std::vector<Eigen::Vector3d> map, world;
      for (const adit::LidarPoint& p : adit::io::readPcdScan((out / "map.pcd").string(), {}, 0, 0).points)
        map.push_back(p.p.cast<double>());
      for (const auto& p : source.simulator().worldPointCloud(0.1)) world.push_back(p.cast<double>());
      summary.map_accuracy = adit::eval::mapAgainstWorld(map, world, summary.final_eval.alignment);
    }
    std::vector<std::string> files{"map:        " + (out / "map.pcd").string(),
                                   "trajectory: " + (out / "trajectory.tum").string() + " (ground truth: " + gt_path + ")"};
    const std::string traj_png = (out / "trajectory.png").string(), map_png = (out / "map.png").string();
    if (summary.final_eval.valid) {
      const auto plot = adit::eval::plotTrajectory(summary.final_eval, traj_png);
      files.push_back(plot.ok ? "plot:       " + traj_png : "plot failed: " + plot.message);
    }
    const auto map_plot = adit::eval::plotMapTopViewFromPcd((out / "map.pcd").string(), map_png,
                                                            adit::eval::readTum((out / "trajectory.tum").string()));
    files.push_back(map_plot.ok ? "map view:   " + map_png : "map view failed: " + map_plot.message);
    const std::string report = adit::pipeline::formatRunReport(summary, files);
    std::ofstream(out / "report.txt") << report;
    fmt::print("\n{}", report);
  });
}
