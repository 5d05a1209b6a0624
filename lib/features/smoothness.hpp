// Per-point smoothness along the scan line and the reliability masks shared by LOAM and LinK3D features.
#pragma once

#include "features/feature_config.hpp"
#include "features/ring_cloud.hpp"

#include <cstdint>
#include <vector>

namespace adit {
class ChunkPool;  // core/chunk_pool.hpp
}

namespace adit::features {

struct PointScores {
  std::vector<float> range;       // |p| (m)
  // Smoothness (LOAM paper eq. 1, normalised to be comparable across ranges and resolutions):
  //   c_i = | sum_j (p_j - p_i) | / sum_j L(i, j)   over the half_window neighbours on each side,
  // L(i, j) the path length along the scan line from p_i to p_j (= |p_j - p_i| on straight runs and at
  // corners). LOAM divides the same sum by |S| |p_i|; dividing by the neighbours' spread instead removes both
  // range (spread grows with range) and angular resolution (16 vs 64 beams), so one threshold fits every
  // sensor: 0 on a straight scan line, cos(a/2) at a corner of interior angle a.
  // -1 where the window is incomplete (ring ends, gaps of missing returns).
  std::vector<float> smoothness;
  // |sum_j (p_j - p_i)| / (2 half_window): distance (m) from p_i to its neighbours' centroid. Range noise
  // moves a point by about its own sigma, so an edge must also clear this noise floor: the scale-free
  // ratio alone would call every point an edge where the beam spacing falls below the noise.
  std::vector<float> offset;
  // Range noise of the sweep (m, one sigma), estimated from the data: the median length of the second
  // differences p_{j-1} - 2 p_j + p_{j+1} of consecutive points less than noise_max_step apart. Where points
  // are that dense the surface's own bend is negligible and a second difference is range noise alone
  // (sqrt(6) sigma, median 1.65 sigma); corners and depth jumps are a minority the median ignores. (Sparser
  // triplets measure the scene: on KITTI's upper rings they read 3-30 cm.) 0 when too few triplets qualify.
  // Edges must clear a multiple of it (LoamConfig::edge_noise_factor).
  float noise = 0.0f;
  // 0 where the point must not become a feature: incomplete window, far side of a depth jump (occluded,
  // it moves with the viewpoint), or a surface nearly parallel to the beam.
  std::vector<std::uint8_t> usable;
};

// Rings are scored independently: with a pool, groups of rings on its threads (the same scores and the same
// noise figure, a median, for any thread count).
PointScores scorePoints(const RingCloud& cloud, const LoamConfig& cfg, ChunkPool* pool = nullptr);

}  // namespace adit::features
