#include "eval/evaluate.hpp"

#include "eval/association.hpp"

namespace adit::eval {

EvalConfig evalConfigFrom(const adit::Config& c) {
  EvalConfig d;
  d.max_time_diff_s = c.get<double>("eval.max_time_diff_s", d.max_time_diff_s);
  d.align = parseAlignMode(c.get<std::string>("eval.align", toString(d.align)));
  d.rpe_deltas_m = c.getList<double>("eval.rpe_deltas_m", d.rpe_deltas_m);
  d.drift_lengths_m = c.getList<double>("eval.drift_lengths_m", d.drift_lengths_m);
  d.drift_step_frames = c.get<int>("eval.drift_step_frames", d.drift_step_frames);
  return d;
}

namespace {

bool finite(const StampedPose& p) { return p.pose.matrix().allFinite(); }

// Pairs with a NaN/inf pose would poison the alignment and every statistic: drop and count them.
std::size_t dropNonFinite(AssociatedTrajectories& m) {
  Trajectory gt, est;
  for (std::size_t k = 0; k < m.gt.size(); ++k) {
    if (!finite(m.gt[k]) || !finite(m.est[k])) continue;
    gt.push_back(m.gt[k]);
    est.push_back(m.est[k]);
  }
  const std::size_t dropped = m.gt.size() - gt.size();
  m.gt = std::move(gt);
  m.est = std::move(est);
  return dropped;
}

}  // namespace

EvalResult evaluate(const Trajectory& gt, const Trajectory& est, const EvalConfig& config) {
  EvalResult r;
  r.align = config.align;
  r.gt_poses = gt.size();
  r.est_poses = est.size();
  AssociatedTrajectories matched = associate(gt, est, toUtime(config.max_time_diff_s));
  r.non_finite_dropped = dropNonFinite(matched);
  r.matched_poses = matched.gt.size();
  if (r.matched_poses == 0) {
    r.message = "no matching timestamps between ground truth (" + std::to_string(gt.size()) + " poses) and estimate (" +
                std::to_string(est.size()) + " poses) within " + std::to_string(config.max_time_diff_s) + " s";
    return r;
  }
  r.valid = true;
  r.gt = matched.gt;
  r.alignment = solveAlignment(matched.gt, matched.est, config.align);
  if (r.non_finite_dropped > 0)
    r.message = std::to_string(r.non_finite_dropped) + " matched pairs with non-finite poses ignored";
  if (r.alignment.degenerate)
    r.message += std::string(r.message.empty() ? "" : "; ") +
                 "alignment degenerate (points on a line or too few): only the centroids were matched";
  r.est_aligned = applyAlignment(matched.est, r.alignment);

  r.ape_errors_m = apeTranslation(r.gt, r.est_aligned);
  r.ape_m = computeStats(r.ape_errors_m);
  for (double delta : config.rpe_deltas_m) {
    const RelativeErrors e = relativeErrors(r.gt, r.est_aligned, pairsByPathLength(r.est_aligned, delta));
    r.rpe.push_back({delta, computeStats(e.translation_m), computeStats(e.rotation_deg)});
  }
  const std::size_t step = config.drift_step_frames > 0 ? static_cast<std::size_t>(config.drift_step_frames) : 1;
  r.drift = kittiDrift(r.gt, r.est_aligned, config.drift_lengths_m, step);

  r.gt_distance_m = pathLength(r.gt);
  r.est_distance_m = pathLength(r.est_aligned);
  r.duration_s = toSeconds(r.gt.back().utime - r.gt.front().utime);
  r.end_point.error_m = r.ape_errors_m.back();
  if (r.gt_distance_m > 0.0) r.end_point.percent_of_distance = 100.0 * r.end_point.error_m / r.gt_distance_m;
  return r;
}

}  // namespace adit::eval
