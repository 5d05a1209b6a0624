// How far the points of a map lie from the true surfaces (the simulator's world, sampled densely), with the
// map placed in the world by the alignment of its run's trajectory onto the ground truth (the alignment of
// the APE; placing it by the first pose alone lets a small heading error at the start swing the far end of
// a long run by metres and hides ghosting behind alignment error). The surface near a point is the plane
// through its nearest samples (the nearest sample itself at corners), so the sampling spacing adds no bias.
// A duplicated roadway shows as points beyond 0.2 m.
#pragma once

#include "eval/alignment.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace adit::eval {

struct MapAccuracy {
  bool valid = false;        // false: no map points or no surface
  std::size_t points = 0;
  double mean_m = 0.0;       // mean point-to-surface distance
  double p95_m = 0.0;        // 95th percentile
  double beyond_02_m = 0.0;  // share of the points farther than 0.2 m
};

// `map_to_world`: the estimate-to-ground-truth alignment (EvalResult::alignment). Distances are capped at
// `max_distance_m` (a point with no surface within it counts as that far).
MapAccuracy mapAgainstWorld(const std::vector<Eigen::Vector3d>& map, const std::vector<Eigen::Vector3d>& surface,
                            const Similarity& map_to_world, double max_distance_m = 2.0);

}  // namespace adit::eval
