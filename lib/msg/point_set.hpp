// Point sets between stages (adit::point_set_t): int16 coordinates at a per-set scale, rings and times only
// where a consumer needs them.
#pragma once

#include "core/types.hpp"

#include <adit/point_set_t.hpp>

#include <vector>

namespace adit::msg {

// The finest scale a set gets (m per count): 1 mm. A set whose largest coordinate exceeds 32.767 m gets
// largest / 32767 instead (3 mm at 100 m): quantisation stays an order below a 16-beam sensor's noise.
constexpr float kPointSetScale = 0.001f;

struct PointSetFields {
  bool rings = false;  // the consumer matches by ring (LOAM sets)
  bool times = false;  // the sweep is not deskewed: the consumer compensates with dt
  // At least this scale: sets of one message that are matched against each other (a sweep's flat points and
  // less-flat points, which contain them) must share one grid, or the same point is quantised to two
  // places up to a scale apart, an offset fixed to the sensor that biased scan-to-scan odometry (issue 16).
  float min_scale = 0.0f;
};

// The scale toPointSet gives these points on their own (m per count).
float pointSetScale(const std::vector<LidarPoint>& points);

adit::point_set_t toPointSet(const std::vector<LidarPoint>& points, PointSetFields fields);
// Points with intensity 0; ring and dt 0 where the set does not carry them. Non-finite or non-positive scale
// gives an empty set.
std::vector<LidarPoint> fromPointSet(const adit::point_set_t& set);
adit::point_set_t emptyPointSet();

}  // namespace adit::msg
