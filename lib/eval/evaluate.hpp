// One call that evaluates an estimated trajectory against ground truth: association, alignment, APE,
// RPE per path-length segment, KITTI drift, end-point error, distance travelled.
#pragma once

#include "core/config.hpp"
#include "core/types.hpp"
#include "eval/alignment.hpp"
#include "eval/metrics.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace adit::eval {

struct EvalConfig {
  // Largest |t_gt - t_est| for two poses to be paired, seconds. evo's t_max_diff default (0.01 s) is
  // a tenth of a 10 Hz sweep, so a pose can never pair with the neighbouring sweep.
  double max_time_diff_s = 0.01;
  // Alignment of the estimate onto the ground truth before any error is computed. SE(3) is what
  // evo_ape -a does and what the paper's tables use; sim3 for monocular-like scale drift.
  AlignMode align = AlignMode::kSE3;
  // RPE path-length deltas, metres (evo_rpe --delta D --delta_unit m, consecutive pairs): 1 m shows
  // local jitter, 10 m odometry quality, 100 m drift over a roadway section.
  std::vector<double> rpe_deltas_m = {1.0, 10.0, 100.0};
  // KITTI odometry benchmark segment lengths, metres (its devkit's 100..800 m).
  std::vector<double> drift_lengths_m = {100, 200, 300, 400, 500, 600, 700, 800};
  // First-frame step of the KITTI drift segments, poses (devkit: 10 = one per second at 10 Hz).
  int drift_step_frames = 10;
};

// Keys (with the defaults above): eval.max_time_diff_s, eval.align (none|se3|sim3),
// eval.rpe_deltas_m (list), eval.drift_lengths_m (list), eval.drift_step_frames.
EvalConfig evalConfigFrom(const adit::Config& c);

struct RpeResult {
  double delta_m = 0.0;
  ErrorStats translation_m;  // count = number of pairs; 0 when the path is shorter than 2 deltas
  ErrorStats rotation_deg;
};

struct EndPointError {
  double error_m = 0.0;               // |p_est,last - p_gt,last| after alignment
  double percent_of_distance = 0.0;   // 100 * error / gt distance travelled (0 if no distance)
};

struct EvalResult {
  bool valid = false;      // false: nothing to evaluate (see message)
  std::string message;     // why not valid, or a warning (e.g. degenerate alignment)
  std::size_t gt_poses = 0, est_poses = 0, matched_poses = 0;
  std::size_t non_finite_dropped = 0;  // matched pairs ignored because a pose had NaN/inf
  AlignMode align = AlignMode::kSE3;
  Similarity alignment;
  ErrorStats ape_m;
  std::vector<RpeResult> rpe;
  KittiDrift drift;
  EndPointError end_point;
  double gt_distance_m = 0.0;   // path length of the matched ground-truth poses
  double est_distance_m = 0.0;  // path length of the matched, aligned estimate
  double duration_s = 0.0;      // first to last matched stamp
  // Per matched pose, for plots: matched gt, aligned estimate, APE error (m).
  Trajectory gt;
  Trajectory est_aligned;
  std::vector<double> ape_errors_m;
};

EvalResult evaluate(const Trajectory& gt, const Trajectory& est, const EvalConfig& config = {});

}  // namespace adit::eval
