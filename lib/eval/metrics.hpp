// Trajectory error metrics over matched pose lists (gt[k] <-> est[k]); definitions follow evo
// (core/metrics.py, core/filters.py) and the KITTI odometry devkit, as noted per function.
#pragma once

#include "core/types.hpp"

#include <cstddef>
#include <vector>

namespace adit::eval {

// Summary of an error list, as evo's PE.get_all_statistics: std is the population std (numpy's
// default ddof=0), median the mean of the two middle values for an even count. All 0 when empty.
struct ErrorStats {
  std::size_t count = 0;
  double max = 0.0, min = 0.0, mean = 0.0, median = 0.0, rmse = 0.0, std = 0.0;
};
ErrorStats computeStats(std::vector<double> errors);

// APE, translation part: |p_est,k - p_gt,k| per matched pose, metres (est already aligned).
std::vector<double> apeTranslation(const Trajectory& gt, const Trajectory& est);

// Sum of the distances between consecutive positions (evo's path_length), metres.
double pathLength(const Trajectory& trajectory);

// evo's filter_pairs_by_path with all_pairs=false: walk the poses accumulating path length; each time
// it reaches >= delta_m, record the index and restart the count at 0. Consecutive recorded indices
// form the pairs. Note (as in evo): the first recorded index is where the path first reaches delta,
// not index 0, so the first segment is not evaluated.
std::vector<std::pair<std::size_t, std::size_t>> pairsByPathLength(const Trajectory& poses, double delta_m);

// RPE over given index pairs (i, j): E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) with Q = gt, P = est (evo's
// rpe_base). Translation error |t(E)| in metres, rotation error |angle(E)| in degrees.
struct RelativeErrors {
  std::vector<double> translation_m;
  std::vector<double> rotation_deg;
};
RelativeErrors relativeErrors(const Trajectory& gt, const Trajectory& est,
                              const std::vector<std::pair<std::size_t, std::size_t>>& pairs);

// KITTI odometry devkit drift (calcSequenceErrors): for every `step_frames`-th first frame and every
// segment length L, the last frame is the first with gt path distance > dist[first] + L; error pose
// (P_first^-1 P_last)^-1 (Q_first^-1 Q_last); translation error / L and rotation angle / L.
// Averaged over all segments of all lengths (the devkit's summary numbers).
struct DriftLength {
  double length_m = 0.0;
  std::size_t segments = 0;
  double translation_percent = 0.0;
  double rotation_deg_per_m = 0.0;
};
struct KittiDrift {
  bool available = false;  // false when the path is shorter than the shortest length
  std::size_t segments = 0;
  double translation_percent = 0.0;   // mean translational error, % of segment length
  double rotation_deg_per_m = 0.0;    // mean rotational error, degrees per metre
  std::vector<DriftLength> per_length;  // only lengths that had segments
};
KittiDrift kittiDrift(const Trajectory& gt, const Trajectory& est, const std::vector<double>& lengths_m,
                      std::size_t step_frames);

}  // namespace adit::eval
