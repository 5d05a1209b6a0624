// Which verified loops join the graph where none has been accepted nearby yet.
//
// One verified loop is never trusted alone (loop.min_consistent_loops): it waits until loops of the
// consistency window agree with it. Agreement alone is not enough in a roadway that repeats: when the odometry
// has drifted by more than the spacing of support arches, an ICP fit one arch off is as consistent with the
// next query's fit one arch off as two true loops are with each other (issue 16's 700 s drive: two such fits
// 6 m off formed a group and the true loops after them were refused). So a group is accepted only when it
// also outnumbers the waiting loops that contradict it; otherwise everything waits for the next loop.
#pragma once

#include "core/types.hpp"

#include <functional>
#include <vector>

namespace adit {

using LoopsAgree = std::function<bool(const LoopConstraint&, const LoopConstraint&)>;

struct LoopConsensus {
  std::vector<LoopConstraint> accepted;  // the new loop and the waiting loops that agree with it; empty: wait
  std::vector<LoopConstraint> pending;   // what waits afterwards
  bool contested = false;                // enough agreed, but as many or more loops contradict them
};

// `pending`: the loops waiting in the consistency window; `loop`: the new one.
LoopConsensus seekConsensus(const std::vector<LoopConstraint>& pending, const LoopConstraint& loop,
                            int min_consistent_loops, const LoopsAgree& agree);

}  // namespace adit
