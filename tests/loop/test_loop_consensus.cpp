// The consensus rule of loop admission (loop/loop_consensus.hpp) on hand-made loops: a loop's "place" is the
// x of its relative pose, and two loops agree when they put the query in the same place.
#include "loop/loop_consensus.hpp"

#include "core/types.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace adit {
namespace {

LoopConstraint loopAt(int query, double place_x) {
  LoopConstraint l;
  l.query_index = query;
  l.match_index = query - 500;
  l.T_match_query.translation().x() = place_x;
  return l;
}

bool samePlace(const LoopConstraint& a, const LoopConstraint& b) {
  return std::abs(a.T_match_query.translation().x() - b.T_match_query.translation().x()) < 0.5;
}

// Feeds loops one by one as the loop closer does; returns the accepted group (empty if none was accepted).
std::vector<LoopConstraint> feed(const std::vector<LoopConstraint>& loops, int min_consistent,
                                 int* contested = nullptr) {
  std::vector<LoopConstraint> pending;
  for (const LoopConstraint& l : loops) {
    Consensus<LoopConstraint> c = seekConsensus(pending, l, min_consistent, samePlace);
    if (contested && c.contested) ++*contested;
    pending = c.pending;
    if (!c.accepted.empty()) return c.accepted;
  }
  return {};
}

TEST(LoopConsensus, TwoAgreeingLoopsAreAccepted) {
  const auto accepted = feed({loopAt(10, 0.0), loopAt(11, 0.1)}, 2);
  ASSERT_EQ(accepted.size(), 2u);
  EXPECT_EQ(accepted.back().query_index, 11);
}

TEST(LoopConsensus, OneLoopAloneWaits) {
  EXPECT_TRUE(feed({loopAt(10, 0.0)}, 2).empty());
  EXPECT_EQ(feed({loopAt(10, 0.0)}, 1).size(), 1u);
}

// Issue 16's 700 s drive: a true loop, then fits one support arch (6 m) off that agree with each other, then
// the true loops again. The old rule accepted the first agreeing pair (the wrong one); the true group must win.
TEST(LoopConsensus, AnAliasedPairDoesNotOutvoteTheTruePlace) {
  const std::vector<LoopConstraint> drive{loopAt(494, 0.0), loopAt(495, 6.0), loopAt(496, 8.0), loopAt(497, 6.0),
                                          loopAt(500, 0.0), loopAt(501, 0.0), loopAt(507, 0.0)};
  int contested = 0;
  const auto accepted = feed(drive, 2, &contested);
  ASSERT_FALSE(accepted.empty());
  for (const LoopConstraint& l : accepted) EXPECT_NEAR(l.T_match_query.translation().x(), 0.0, 1e-9);
  EXPECT_EQ(accepted.back().query_index, 507);  // 4 true against 3 contradicting
  EXPECT_EQ(accepted.size(), 4u);
  EXPECT_EQ(contested, 3);  // at 497, 500 and 501 enough agreed but as many contradicted
}

TEST(LoopConsensus, ContradictingLoopsStayWaitingWhenAGroupIsAccepted) {
  std::vector<LoopConstraint> pending{loopAt(10, 6.0)};
  Consensus<LoopConstraint> c = seekConsensus(pending, loopAt(11, 0.0), 2, samePlace);
  EXPECT_TRUE(c.accepted.empty());
  EXPECT_FALSE(c.contested);  // one agreeing loop is not enough: waiting, not contested
  c = seekConsensus(c.pending, loopAt(12, 0.0), 2, samePlace);
  ASSERT_EQ(c.accepted.size(), 2u);  // 2 against 1
  ASSERT_EQ(c.pending.size(), 1u);
  EXPECT_EQ(c.pending[0].query_index, 10);
}

}  // namespace
}  // namespace adit
