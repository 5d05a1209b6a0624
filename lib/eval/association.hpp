// Pairing two trajectories by timestamp, the way evo's sync.associate_trajectories does it.
#pragma once

#include "core/types.hpp"

#include <cstddef>
#include <cstdint>

namespace adit::eval {

struct AssociatedTrajectories {
  Trajectory gt;   // gt[k] and est[k] were matched to each other
  Trajectory est;
  std::size_t gt_input = 0;   // poses in the ground truth before association
  std::size_t est_input = 0;  // poses in the estimate before association
};

// evo's rule: for every stamp of the SHORTER trajectory (the estimate when both are equally long), take
// the closest stamp of the longer one (first of equals); keep the pair if |dt| <= max_diff_us. A stamp
// of the longer trajectory can therefore be used twice. Missing or extra stamps on either side simply
// drop out. Result is empty if nothing matches.
AssociatedTrajectories associate(const Trajectory& gt, const Trajectory& est, std::int64_t max_diff_us = 10000);

}  // namespace adit::eval
