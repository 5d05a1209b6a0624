#include "loop/loop_consensus.hpp"

namespace adit {

LoopConsensus seekConsensus(const std::vector<LoopConstraint>& pending, const LoopConstraint& loop,
                            int min_consistent_loops, const LoopsAgree& agree) {
  LoopConsensus out;
  std::vector<LoopConstraint> group, against;
  for (const LoopConstraint& p : pending) (agree(p, loop) ? group : against).push_back(p);
  const int agreeing = static_cast<int>(group.size()) + 1;
  const bool enough = agreeing >= min_consistent_loops;
  out.contested = enough && agreeing <= static_cast<int>(against.size());
  if (enough && !out.contested) {
    out.accepted = std::move(group);
    out.accepted.push_back(loop);
    out.pending = std::move(against);
    return out;
  }
  out.pending = pending;
  out.pending.push_back(loop);
  return out;
}

}  // namespace adit
