// Voxel downsampling as a streaming accumulator: points go in one by one, one centroid per occupied voxel
// comes out, in order of first occurrence (deterministic: the hash table is used for lookups only).
#pragma once

#include "core/types.hpp"

#include <cstdint>
#include <vector>

namespace adit::features {

class VoxelCentroids {
 public:
  // leaf: voxel size (m), > 0. expected_points: a hint for the first table size (the table grows as needed).
  VoxelCentroids(float leaf, std::size_t expected_points);

  // Adds p to its voxel. Points with non-finite or absurd coordinates (a hostile message) have no voxel
  // and are skipped: converting them to integers would be undefined.
  void add(const LidarPoint& p);

  // One point per voxel at the centroid of its points, with the ring / time / intensity of the first.
  std::vector<LidarPoint> take();

 private:
  void grow();
  std::size_t bucket(std::uint64_t key) const { return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_); }

  float inv_leaf_;
  int shift_ = 64;                    // bucket = top bits of the multiplied key
  std::vector<std::int32_t> table_;   // bucket -> voxel index, -1 = empty (open addressing, linear probing)
  std::vector<std::uint64_t> keys_;   // per voxel: packed integer coordinates
  std::vector<LidarPoint> out_;       // per voxel: first point, its position holding the running sum
  std::vector<std::int32_t> counts_;  // per voxel: points summed
  std::uint64_t last_key_ = 0;        // consecutive points of a ring mostly share a voxel: skip the lookup
  std::int32_t last_voxel_ = -1;
};

}  // namespace adit::features
