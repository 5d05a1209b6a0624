#include "pipeline/run_summary.hpp"

#include "eval/trajectory_io.hpp"
#include "runtime/lcm_log.hpp"

#include <fmt/format.h>

#include <filesystem>

namespace adit::pipeline {
namespace fs = std::filesystem;

RunSummary summarizeRun(const ReplayReport& replay, const std::string& out_dir, const Trajectory& ground_truth,
                        eval::AlignMode align) {
  RunSummary s;
  s.replay = replay;
  const fs::path dir(out_dir);
  eval::EvalConfig config;
  config.align = align;
  if (fs::exists(dir / "trajectory.tum"))
    s.final_eval = eval::evaluate(ground_truth, eval::readTum((dir / "trajectory.tum").string()), config);
  if (fs::exists(dir / "odometry.tum"))
    s.odometry_eval = eval::evaluate(ground_truth, eval::readTum((dir / "odometry.tum").string()), config);
  runtime::LogReader log((dir / "output.lcmlog").string());
  runtime::LogEvent e;
  while (log.next(e)) s.loops += e.channel == "LOOP_CLOSURE";
  s.ms_per_sweep = replay.sweeps > 0 ? replay.wall_seconds * 1e3 / static_cast<double>(replay.sweeps) : 0.0;
  s.realtime_factor = replay.wall_seconds > 0 ? replay.sensor_seconds / replay.wall_seconds : 0.0;
  return s;
}

std::string formatRunReport(const RunSummary& s, const std::vector<std::string>& files) {
  std::string out = "adit run report\n";
  out += fmt::format("  distance travelled   {:.1f} m in {:.0f} s ({} sweeps)\n", s.final_eval.gt_distance_m,
                     s.replay.sensor_seconds, s.replay.sweeps);
  out += fmt::format("  loops closed         {}\n", s.loops);
  if (s.final_eval.valid) {
    out += fmt::format("  APE rmse             {:.3f} m (max {:.3f} m) after loop closure, {}-aligned\n",
                       s.final_eval.ape_m.rmse, s.final_eval.ape_m.max, eval::toString(s.final_eval.align));
    if (s.final_eval.align == eval::AlignMode::kSim3)
      out += fmt::format("                       scale of the estimate {:.4f}\n", s.final_eval.alignment.scale);
    if (s.odometry_eval.valid)
      out += fmt::format("                       {:.3f} m (max {:.3f} m) before\n", s.odometry_eval.ape_m.rmse,
                         s.odometry_eval.ape_m.max);
    out += fmt::format("  end-point error      {:.3f} m ({:.2f} % of the distance)\n", s.final_eval.end_point.error_m,
                       s.final_eval.end_point.percent_of_distance);
  } else {
    out += "  APE                  not available: " + s.final_eval.message + "\n";
  }
  if (s.map_accuracy.valid)
    out += fmt::format("  map against world    {:.3f} m mean, {:.3f} m at the 95th percentile, {:.2f} % of {} points "
                       "beyond 0.2 m\n",
                       s.map_accuracy.mean_m, s.map_accuracy.p95_m, 100.0 * s.map_accuracy.beyond_02_m,
                       s.map_accuracy.points);
  out += fmt::format("  speed                {:.1f} ms per sweep, {:.1f}x real time, peak memory {:.0f} MB\n",
                     s.ms_per_sweep, s.realtime_factor, s.replay.peak_memory_mb);
  for (const auto& f : files) out += "  " + f + "\n";
  return out;
}

}  // namespace adit::pipeline
