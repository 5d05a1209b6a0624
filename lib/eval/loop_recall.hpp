// Precision and recall of loop closure against a ground-truth trajectory (issue 16's aliased workings).
//
// Recall is counted per revisit, not per keyframe: the ground truth is sampled every `sample_spacing_m` of
// travel, a sample is a revisit when an earlier sample lies within `revisit_radius_m` and is far enough back
// that the loop closer may match it (its own exclusion of recent keyframes and seconds), and each run of
// consecutive revisit samples (the robot passing once more through a place it has mapped) is one revisit. A
// revisit is closed when a true loop's query falls in it. Precision is the share of accepted loops that are
// true; the caller judges each loop against the truth (its relative pose error).
#pragma once

#include "core/types.hpp"

#include <cstdint>
#include <vector>

namespace adit::eval {

struct LoopRecallConfig {
  double sample_spacing_m = 1.0;   // ground truth sampled this often (the loop closer's keyframe distance)
  double revisit_radius_m = 3.0;   // an earlier place this close is revisited
  double min_travel_m = 50.0;      // ...when at least this much driving lies between (loop.exclude_recent_keyframes)
  double min_age_s = 30.0;         // ...and at least this much time (loop.exclude_recent_seconds)
};

struct JudgedLoop {
  std::int64_t query_utime = 0;
  bool correct = false;  // relative pose close to the truth
};

struct LoopRecall {
  int accepted = 0, correct = 0, wrong = 0;
  int revisits = 0, revisits_closed = 0;
  double precision() const { return accepted > 0 ? static_cast<double>(correct) / accepted : 1.0; }
  double recall() const { return revisits > 0 ? static_cast<double>(revisits_closed) / revisits : 1.0; }
};

// truth: ground-truth poses in time order.
LoopRecall loopRecall(const Trajectory& truth, const std::vector<JudgedLoop>& loops, const LoopRecallConfig& config = {});

}  // namespace adit::eval
