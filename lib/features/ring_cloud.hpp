// A sweep organised for per-ring processing: the layout every later feature step works on.
#pragma once

#include "core/types.hpp"

#include <vector>

namespace adit::features {

// Points grouped by ring (ring 0 first) and, inside a ring, in firing order (ascending dt), which for a
// spinning lidar is azimuth order: the neighbours of a point along its scan line are the points next to it.
struct RingCloud {
  std::vector<LidarPoint> points;
  std::vector<int> ring_begin{0};  // ring r holds points [ring_begin[r], ring_begin[r + 1])

  int numRings() const { return static_cast<int>(ring_begin.size()) - 1; }
  int ringSize(int r) const { return ring_begin[r + 1] - ring_begin[r]; }
  bool empty() const { return points.empty(); }
};

}  // namespace adit::features
