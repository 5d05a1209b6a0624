// adit bench ablation <log> --gt <gt> [--align se3|sim3|none]: the paper's before/after comparison on one log:
//   (a) plain A-LOAM, (b) + LinK3D, (c) + LinK3D + Scan Context loop closure; one APE table.
// adit bench pipeline [--sensor vlp16|hdl64] [--log LOG] [--json FILE]: per-stage wall and CPU ms per sweep
//   (median, p95), throughput, real-time factor and peak memory of the whole pipeline. With --live: the real
//   processes in real time over UDP (private network namespace), LIDAR_POINTS -> ODOM_MAPPED latency.
// adit bench compare a.json b.json [--tolerance PCT]: one line per figure with its change; regressions flagged.
#include "commands.hpp"

#include "eval/report.hpp"
#include "eval/trajectory_io.hpp"
#include "io/atomic_file.hpp"
#include "pipeline/bench_figures.hpp"
#include "pipeline/live_status.hpp"
#include "pipeline/run_summary.hpp"
#include "runtime/process.hpp"
#include "sources/sim_source.hpp"

#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace {

struct Variant {
  std::string name;
  std::vector<std::string> extra_configs;  // relative to launch/config
  std::vector<std::string> stages;
};

const std::vector<Variant>& ablationVariants() {
  static const std::vector<Variant> variants{
      {"A-LOAM", {"aloam.yaml"}, {"feature", "odometry", "mapper"}},
      {"+ LinK3D", {}, {"feature", "odometry", "mapper"}},
      {"+ LinK3D + Scan Context", {}, {"feature", "odometry", "mapper", "loop_closer"}},
  };
  return variants;
}

fs::path aditRoot() { return fs::weakly_canonical(fs::path(executableDir()) / ".." / ".."); }

void registerAblation(CLI::App& bench) {
  struct Args {
    std::string log, gt, out_dir, align = "se3";
    std::vector<std::string> configs;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = bench.add_subcommand("ablation", "Run a log as plain A-LOAM, + LinK3D, + LinK3D + Scan Context; print the APE table");
  cmd->add_option("log", a->log, "Input LCM log")->required()->check(CLI::ExistingFile);
  cmd->add_option("--gt", a->gt, "Ground truth (TUM, T_world_lidar at the sweeps' utimes)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--config", a->configs, "Base configuration (default launch/config/pipeline.yaml; repeatable)");
  cmd->add_option("-o,--out", a->out_dir, "Output folder, one sub-folder per variant (default <adit>/logs/ablation)");
  cmd->add_option("--align", a->align,
                  "Alignment onto the ground truth before the APE: se3 (default, as the paper's tables), sim3 (also "
                  "the scale: ground truth known only up to scale), none")
      ->check(CLI::IsMember({"se3", "sim3", "none"}));
  cmd->callback([a] {
    const adit::eval::AlignMode align = adit::eval::parseAlignMode(a->align);
    const fs::path root = aditRoot();
    std::vector<std::string> base = a->configs;
    if (base.empty()) base.push_back((root / "launch" / "config" / "pipeline.yaml").string());
    const fs::path out = a->out_dir.empty() ? root / "logs" / "ablation" : fs::path(a->out_dir);
    const adit::Trajectory gt = adit::eval::readTum(a->gt);
    std::vector<adit::eval::ApeTableRow> rows;
    std::string loops;
    for (const Variant& v : ablationVariants()) {
      std::vector<std::string> configs = base;
      for (const auto& f : v.extra_configs) configs.push_back((root / "launch" / "config" / f).string());
      adit::pipeline::ReplayOptions options;
      options.input_log = a->log;
      options.out_dir = (out / v.name.substr(v.name.find_first_not_of("+ "))).string();
      for (char& c : options.out_dir) if (c == ' ' || c == '+') c = '_';
      options.config = adit::runtime::loadConfig(configs);
      options.stages = v.stages;
      options.record = "^(LOOP_CLOSURE|POSE_GRAPH)$";
      fmt::print("ablation: {} ...\n", v.name);
      std::fflush(stdout);
      const auto summary = adit::pipeline::summarizeRun(adit::pipeline::runReplay(options), options.out_dir, gt, align);
      if (!summary.final_eval.valid) throw std::runtime_error(v.name + ": " + summary.final_eval.message);
      rows.push_back({v.name, summary.final_eval.ape_m, summary.ms_per_sweep});
      loops += fmt::format("  {}: {} loop(s) closed{}, output in {}\n", v.name, summary.loops,
                           align == adit::eval::AlignMode::kSim3
                               ? fmt::format(", scale {:.4f}", summary.final_eval.alignment.scale)
                               : std::string(),
                           options.out_dir);
    }
    const std::string table = adit::eval::formatApeTable(rows, "APE (m) against ground truth, " + a->align + "-aligned: " + a->log);
    std::ofstream(out / "ablation.txt") << table << loops;
    fmt::print("\n{}{}", table, loops);
  });
}

struct PipelineBenchArgs {
  std::string sensor = "vlp16", log, world = "roadway-loop", json;
  std::vector<std::string> configs;
  double duration_s = 60;
  bool live = false;
  bool serial = false;
};

std::string shellQuoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// `adit bench pipeline --live`: launch/sim.launch.yaml (the simulator in real time and the four stage
// processes over UDP multicast) inside a private network namespace, recording STATUS only; the figures are
// what the processes' last STATUS said, the mapper's LIDAR_POINTS -> ODOM_MAPPED latency first.
int runLiveBench(const PipelineBenchArgs& a) {
  const fs::path root = aditRoot();
  const std::string self = (fs::path(executableDir()) / "adit").string();
  if (std::getenv("ADIT_IN_NETNS") == nullptr) {  // re-run inside the namespace (exit 77: none can be made)
    std::string command = "bash " + shellQuoted((root / "tests" / "integration" / "netns.sh").string()) + " " +
                          shellQuoted(self) + " bench pipeline --live --world " + shellQuoted(a.world) +
                          " --sensor " + shellQuoted(a.sensor) + fmt::format(" --duration {}", a.duration_s);
    for (const auto& c : a.configs) command += " --config " + shellQuoted(c);
    if (!a.json.empty()) command += " --json " + shellQuoted(fs::absolute(a.json).string());
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
  }
  if (!a.configs.empty()) fmt::print("  note: --live runs launch/sim.launch.yaml with its own configuration; --config is ignored\n");
  const fs::path work = fs::temp_directory_path() / ("adit_bench_live_" + std::to_string(::getpid()));
  fs::create_directories(work);
  fmt::print("live pipeline benchmark: {} {} for {:.0f} s in real time, real processes over UDP ...\n", a.world, a.sensor,
             a.duration_s);
  std::fflush(stdout);
  const std::string command = shellQuoted(self) + " launch " + shellQuoted((root / "launch" / "sim.launch.yaml").string()) +
                              " --set WORLD=" + shellQuoted(a.world) + " --set SENSOR=" + shellQuoted(a.sensor) +
                              fmt::format(" --set DURATION={}", a.duration_s) + " --set RECORD='^STATUS_.*$'" +
                              " --log-dir " + shellQuoted(work.string()) + " --quiet";
  const int status = std::system(command.c_str());
  std::map<std::string, adit::status_t> last;
  for (const auto& entry : fs::recursive_directory_iterator(work)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("record", 0) != 0 || entry.path().extension() != ".lcmlog") continue;
    for (auto& [process, s] : adit::pipeline::lastStatusByProcess(entry.path().string())) last[process] = std::move(s);
  }
  fs::remove_all(work);
  if (last.empty()) {
    fmt::print(stderr, "error adit: the live run recorded no STATUS (adit launch exit status {})\n", status);
    return 1;
  }
  const auto figures = adit::pipeline::liveFigures(last);
  for (const auto& f : figures) fmt::print("  {:<36} {:>10.2f} {}\n", f.name, f.value, f.unit);
  if (!a.json.empty()) {
    adit::io::writeFileAtomically(a.json, adit::pipeline::benchFiguresJson(figures, "live " + a.world + " " + a.sensor));
    fmt::print("  figures written to {}\n", a.json);
  }
  return 0;
}

void registerPipelineBench(CLI::App& bench) {
  using Args = PipelineBenchArgs;
  auto a = std::make_shared<Args>();
  auto* cmd = bench.add_subcommand("pipeline", "Time every stage over a simulated run (or a log): ms per sweep, throughput, memory");
  cmd->add_option("--sensor", a->sensor, "Simulated sensor: vlp16 | rs16 | hdl64")->check(CLI::IsMember({"vlp16", "rs16", "hdl64"}));
  cmd->add_option("--world", a->world, "Simulated world");
  cmd->add_option("--duration", a->duration_s, "Simulated seconds")->check(CLI::PositiveNumber);
  cmd->add_option("--log", a->log, "Time this log instead of a simulation")->check(CLI::ExistingFile);
  cmd->add_option("--config", a->configs, "Configuration (default launch/config/pipeline.yaml)");
  cmd->add_option("--json", a->json, "Also write the figures to this JSON file (for adit bench compare)");
  cmd->add_flag("--serial", a->serial, "Every stage on one thread (default: two pipelined groups, as adit replay)");
  cmd->add_flag("--live", a->live, "Run the real processes in real time over UDP in a private network namespace "
                                   "and report the LIDAR_POINTS -> ODOM_MAPPED latency from their STATUS");
  cmd->callback([a] {
    if (a->live) {
      if (!a->log.empty()) throw CLI::ValidationError("--live", "simulates in real time; it takes no --log");
      if (const int code = runLiveBench(*a); code != 0) throw CLI::RuntimeError(code);
      return;
    }
    const fs::path root = aditRoot();
    std::vector<std::string> configs = a->configs;
    if (configs.empty()) configs.push_back((root / "launch" / "config" / "pipeline.yaml").string());
    adit::pipeline::ReplayOptions options;
    options.config = adit::runtime::loadConfig(configs);
    options.out_dir = (fs::temp_directory_path() / ("adit_bench_" + std::to_string(::getpid()))).string();
    options.record = "^$";  // time the stages, not the disk
    options.pipelined = !a->serial;
    std::unique_ptr<adit::sources::SimSource> sim;
    std::string input = a->log;
    if (a->log.empty()) {
      adit::sim::SimConfig s = adit::sim::simConfigFrom(options.config, a->world, options.config.get<std::uint64_t>("sim.seed", 1));
      s.sensor = a->sensor;
      s.duration_s = a->duration_s;
      sim = std::make_unique<adit::sources::SimSource>(s, adit::sources::SimChannels{});
      options.source = sim.get();
      input = fmt::format("simulated {} {} for {:.0f} s", a->world, a->sensor, a->duration_s);
    } else {
      options.input_log = a->log;
    }
    const auto r = adit::pipeline::runReplay(options);
    fs::remove_all(options.out_dir);
    fmt::print("pipeline benchmark: {} ({} sweeps)\n", input, r.sweeps);
    fmt::print("  {:<12} {:>10} {:>10} {:>10} {:>10} {:>10}\n", "stage", "wall med", "wall p95", "wall max", "cpu med",
               "cpu/sweep");
    const double sweeps = r.sweeps > 0 ? static_cast<double>(r.sweeps) : 1.0;
    for (const auto& t : r.timing) {
      fmt::print("  {:<12} {:>10.2f} {:>10.2f} {:>10.2f} {:>10.2f} {:>10.2f}\n", t.stage, t.median_ms, t.p95_ms, t.max_ms,
                 t.cpu_median_ms, t.cpu_total_ms / sweeps);
      if (const double helpers = adit::pipeline::helperCpuMs(t); helpers >= 0)
        fmt::print("  {:<12} {:>10} {:>10} {:>10} {:>10} {:>10.2f}\n", "  + helpers", "", "", "", "", helpers / sweeps);
    }
    const double per_sweep = r.wall_seconds * 1e3 / sweeps;
    fmt::print("  (ms; cpu = CPU time of the stage's own thread; \"+ helpers\": its other threads (search threads, "
               "features.threads, the loop closer's worker), where it has any)\n");
    fmt::print("  end to end: {:.1f} ms per sweep (incl. simulation when simulated), {:.1f} sweeps/s, {:.1f}x real time, "
               "process CPU {:.1f} ms per sweep (every thread), peak memory {:.0f} MB\n", per_sweep,
               per_sweep > 0 ? 1e3 / per_sweep : 0.0, r.wall_seconds > 0 ? r.sensor_seconds / r.wall_seconds : 0.0,
               r.process_cpu_seconds * 1e3 / sweeps, r.peak_memory_mb);
    if (!a->json.empty()) {
      adit::io::writeFileAtomically(a->json, adit::pipeline::benchFiguresJson(adit::pipeline::benchFigures(r), input));
      fmt::print("  figures written to {}\n", a->json);
    }
  });
}

void registerCompare(CLI::App& bench) {
  struct Args {
    std::vector<std::string> files;
    bool pairs = false;
    double tolerance_pct = 10.0;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = bench.add_subcommand("compare", "Compare `adit bench pipeline --json` files, one line per figure; "
                                              "exit status 1 when a figure got worse by more than the tolerance");
  cmd->add_option("files", a->files,
                  "BEFORE AFTER: the reference build's figures and the judged build's; with --pairs, runs of the "
                  "two builds taken in turn: BEFORE AFTER BEFORE AFTER ...")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_flag("--pairs", a->pairs,
                "Each figure's change is the median over the pairs (with its range): what a machine whose speed "
                "drifts still tells apart (scripts/bench_pairs.sh takes such runs)");
  cmd->add_option("--tolerance", a->tolerance_pct, "Change in % beyond which a worse figure is a regression (default 10)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([a] {
    const std::size_t n = a->files.size();
    if (n < 2 || n % 2 != 0 || (!a->pairs && n != 2))
      throw CLI::ValidationError("files", a->pairs ? "--pairs takes BEFORE AFTER files in turn: an even number"
                                                   : "two files, BEFORE and AFTER (several runs: --pairs)");
    std::vector<std::vector<adit::pipeline::BenchFigure>> before, after;
    for (std::size_t i = 0; i < n; ++i) (i % 2 ? after : before).push_back(adit::pipeline::readBenchFigures(a->files[i]));
    const auto changes = adit::pipeline::compareFigurePairs(before, after, a->tolerance_pct);
    int regressions = 0;
    for (const auto& c : changes) {
      if (c.missing) {
        if (n == 2) fmt::print("  {:<36} only in {}\n", c.name, c.before == 0 && c.after != 0 ? a->files[1] : a->files[0]);
        else fmt::print("  {:<36} missing from some of the files\n", c.name);
        continue;
      }
      regressions += c.regression ? 1 : 0;
      const std::string range = n > 2 ? fmt::format("  ({:+.1f} .. {:+.1f})", c.change_min_pct, c.change_max_pct) : "";
      fmt::print("  {:<36} {:>10.2f} -> {:>10.2f} {:<3} {:>+7.1f} %{}{}\n", c.name, c.before, c.after, c.unit, c.change_pct,
                 range, c.regression ? "  REGRESSION" : "");
    }
    if (n > 2) fmt::print("{} pairs: medians of the pairs' changes\n", n / 2);
    fmt::print("{} regression(s) beyond {:.0f} %\n", regressions, a->tolerance_pct);
    if (regressions > 0) throw CLI::RuntimeError(1);
  });
}

}  // namespace

void registerBenchCommand(CLI::App& app) {
  auto* bench = app.add_subcommand("bench", "Benchmarks: the ablation table and the pipeline's speed");
  bench->require_subcommand(1);
  registerAblation(*bench);
  registerPipelineBench(*bench);
  registerCompare(*bench);
}
