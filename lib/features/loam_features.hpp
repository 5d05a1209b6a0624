// LOAM edge and planar feature selection (Zhang & Singh 2014, as in A-LOAM's scanRegistration, on the
// range-independent smoothness of smoothness.hpp and with occluded / beam-parallel points excluded).
#pragma once

#include "features/feature_config.hpp"
#include "features/ring_cloud.hpp"
#include "features/smoothness.hpp"

#include <vector>

namespace adit::features {

struct LoamFeatures {
  std::vector<LidarPoint> sharp;       // strongest edges: up to max_sharp per ring sector
  std::vector<LidarPoint> less_sharp;  // edges incl. the sharp ones: up to max_less_sharp per ring sector
  std::vector<LidarPoint> flat;        // flattest points: up to max_flat per ring sector
  std::vector<LidarPoint> less_flat;   // every usable non-edge point, voxel downsampled (less_flat_voxel)
};

// Each ring's evaluated span is cut into cfg.sectors equal parts; in each, edges are picked by decreasing
// smoothness and planes by increasing smoothness, each pick suppressing its half_window neighbours on the
// same surface so features spread out.
LoamFeatures selectLoamFeatures(const RingCloud& cloud, const PointScores& scores, const LoamConfig& cfg);

}  // namespace adit::features
