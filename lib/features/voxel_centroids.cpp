#include "features/voxel_centroids.hpp"

#include <cmath>

namespace adit::features {

VoxelCentroids::VoxelCentroids(float leaf, std::size_t expected_points) : inv_leaf_(1.0f / leaf) {
  // Downsampling keeps a fraction of the points: start with room for a quarter of them at load <= 1/2.
  std::size_t capacity = 64;
  shift_ = 58;
  while (capacity < expected_points / 2) {
    capacity <<= 1;
    --shift_;
  }
  table_.assign(capacity, -1);
  const std::size_t voxels = expected_points / 4 + 16;
  keys_.reserve(voxels);
  out_.reserve(voxels);
  counts_.reserve(voxels);
}

void VoxelCentroids::grow() {
  table_.assign(table_.size() * 2, -1);
  --shift_;
  const std::size_t mask = table_.size() - 1;
  for (std::size_t v = 0; v < keys_.size(); ++v) {
    std::size_t h = bucket(keys_[v]);
    while (table_[h] >= 0) h = (h + 1) & mask;
    table_[h] = static_cast<std::int32_t>(v);
  }
}

void VoxelCentroids::addToOtherVoxel(std::uint64_t key, const LidarPoint& p) {
  const std::size_t mask = table_.size() - 1;
  std::size_t h = bucket(key);
  while (table_[h] >= 0 && keys_[static_cast<std::size_t>(table_[h])] != key) h = (h + 1) & mask;
  last_key_ = key;
  if (table_[h] >= 0) {
    last_voxel_ = table_[h];
    out_[static_cast<std::size_t>(last_voxel_)].p += p.p;
    ++counts_[static_cast<std::size_t>(last_voxel_)];
    return;
  }
  last_voxel_ = static_cast<std::int32_t>(keys_.size());
  table_[h] = last_voxel_;
  keys_.push_back(key);
  out_.push_back(p);
  counts_.push_back(1);
  if (2 * keys_.size() > table_.size()) grow();
}

std::vector<LidarPoint> VoxelCentroids::take() {
  for (std::size_t v = 0; v < out_.size(); ++v) out_[v].p /= static_cast<float>(counts_[v]);
  last_voxel_ = -1;
  return std::move(out_);
}

}  // namespace adit::features
