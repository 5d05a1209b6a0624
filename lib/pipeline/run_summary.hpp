// What a run achieved against ground truth: the numbers of the demo report and of the ablation table.
#pragma once

#include "core/types.hpp"
#include "eval/evaluate.hpp"
#include "eval/map_accuracy.hpp"
#include "pipeline/replay.hpp"

#include <string>
#include <vector>

namespace adit::pipeline {

struct RunSummary {
  ReplayReport replay;
  eval::EvalResult final_eval;     // trajectory.tum (loop-corrected) against ground truth
  eval::EvalResult odometry_eval;  // odometry.tum (before loop correction) against ground truth
  int loops = 0;                   // LOOP_CLOSURE messages in output.lcmlog
  double ms_per_sweep = 0;         // wall time of the whole pipeline per sweep
  double realtime_factor = 0;      // sensor seconds per wall second
  eval::MapAccuracy map_accuracy;  // map.pcd against the true surfaces, when they are known (the simulator's)
};

// Reads out_dir's trajectories (and LOOP_CLOSURE from output.lcmlog, when it was recorded) after a replay,
// aligned onto the ground truth with `align` before any error (sim3 where the truth is known only up to scale).
RunSummary summarizeRun(const ReplayReport& replay, const std::string& out_dir, const Trajectory& ground_truth,
                        eval::AlignMode align = eval::AlignMode::kSE3);

// The short report the demo ends with.
std::string formatRunReport(const RunSummary& summary, const std::vector<std::string>& files);

}  // namespace adit::pipeline
