// The k nearest so far of a neighbour search, kept in the caller's arrays (squared distances ascending, their
// indices beside them): a short insertion, no allocation. Shared by the KD-tree and the odometry's ring walk.
#pragma once

#include <algorithm>

namespace adit {

// Inserts (dist, index) among the `count` kept (count grows up to k). The caller has checked that dist is
// below the k-th best; an equal distance keeps the earlier-met point first, so a search is deterministic.
template <class Index>
void insertKBest(float dist, Index index, int k, int& count, float* dists, Index* indices) {
  int i = std::min(count, k - 1);
  for (; i > 0 && dists[i - 1] > dist; --i) {
    dists[i] = dists[i - 1];
    indices[i] = indices[i - 1];
  }
  dists[i] = dist;
  indices[i] = index;
  count = std::min(count + 1, k);
}

}  // namespace adit
