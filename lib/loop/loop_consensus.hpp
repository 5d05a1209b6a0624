// Which verified matches of a place become trusted where none has been accepted nearby yet: the loop
// closer's loops, and the relocaliser's first fix in a saved map.
//
// One verified match is never trusted alone (loop.min_consistent_loops, reloc.min_consistent_fixes): it waits
// until matches of the consistency window agree with it. Agreement alone is not enough in a roadway that
// repeats: when the odometry has drifted by more than the spacing of support arches, an ICP fit one arch off
// is as consistent with the next query's fit one arch off as two true matches are with each other (issue 16's
// 700 s drive: two such loops 6 m off formed a group and the true loops after them were refused). So a group
// is accepted only when it also outnumbers the waiting matches that contradict it; otherwise all wait.
#pragma once

#include <vector>

namespace adit {

template <class Match>
struct Consensus {
  std::vector<Match> accepted;  // the new match and the waiting ones that agree with it; empty: wait
  std::vector<Match> pending;   // what waits afterwards
  bool contested = false;       // enough agreed, but as many or more contradict them
  bool contradicted = false;    // some waiting match contradicts the new one
};

// `pending`: the matches waiting in the consistency window; `match`: the new one; agree(a, b): whether two
// matches put the robot in the same place.
template <class Match, class Agree>
Consensus<Match> seekConsensus(const std::vector<Match>& pending, const Match& match, int min_consistent,
                               const Agree& agree) {
  Consensus<Match> out;
  std::vector<Match> group, against;
  for (const Match& p : pending) (agree(p, match) ? group : against).push_back(p);
  const int agreeing = static_cast<int>(group.size()) + 1;
  const bool enough = agreeing >= min_consistent;
  out.contradicted = !against.empty();
  out.contested = enough && agreeing <= static_cast<int>(against.size());
  if (enough && !out.contested) {
    out.accepted = std::move(group);
    out.accepted.push_back(match);
    out.pending = std::move(against);
    return out;
  }
  out.pending = pending;
  out.pending.push_back(match);
  return out;
}

}  // namespace adit
