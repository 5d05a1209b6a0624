#include "eval/association.hpp"

#include <algorithm>
#include <cstdlib>

namespace adit::eval {
namespace {

std::int64_t absDiff(std::int64_t a, std::int64_t b) { return a > b ? a - b : b - a; }

// Index of the stamp in `stamps` closest to t; the first one on ties (numpy argmin).
std::size_t closest(const Trajectory& stamps, bool sorted, std::int64_t t) {
  if (!sorted) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < stamps.size(); ++i)
      if (absDiff(stamps[i].utime, t) < absDiff(stamps[best].utime, t)) best = i;
    return best;
  }
  const auto it = std::lower_bound(stamps.begin(), stamps.end(), t,
                                   [](const StampedPose& p, std::int64_t value) { return p.utime < value; });
  std::size_t best = static_cast<std::size_t>(it - stamps.begin());
  if (best == stamps.size()) best = stamps.size() - 1;
  if (best > 0 && absDiff(stamps[best - 1].utime, t) <= absDiff(stamps[best].utime, t)) --best;
  while (best > 0 && stamps[best - 1].utime == stamps[best].utime) --best;
  return best;
}

}  // namespace

AssociatedTrajectories associate(const Trajectory& gt, const Trajectory& est, std::int64_t max_diff_us) {
  AssociatedTrajectories out;
  out.gt_input = gt.size();
  out.est_input = est.size();
  if (gt.empty() || est.empty()) return out;

  const bool gt_longer = gt.size() >= est.size();  // evo: traj_2 (est) is "longer" only if strictly longer
  const Trajectory& shorter = gt_longer ? est : gt;
  const Trajectory& longer = gt_longer ? gt : est;
  const bool sorted = std::is_sorted(longer.begin(), longer.end(),
                                     [](const StampedPose& a, const StampedPose& b) { return a.utime < b.utime; });
  for (const StampedPose& s : shorter) {
    const StampedPose& l = longer[closest(longer, sorted, s.utime)];
    if (absDiff(l.utime, s.utime) > max_diff_us) continue;
    out.gt.push_back(gt_longer ? l : s);
    out.est.push_back(gt_longer ? s : l);
  }
  return out;
}

}  // namespace adit::eval
