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

namespace {

// floor(v) as an integer, for |v| <= 1e15 (exact: such floats convert to int64 without overflow).
std::int64_t floorToInt(float v) {
  const auto t = static_cast<std::int64_t>(v);  // truncation toward zero
  return static_cast<float>(t) > v ? t - 1 : t;
}

}  // namespace

void VoxelCentroids::add(const LidarPoint& p) {
  const float x = p.p.x() * inv_leaf_, y = p.p.y() * inv_leaf_, z = p.p.z() * inv_leaf_;
  // Written so that NaN fails too. A float beyond 2^23 is an integer, so |v| <= 1e15 is |floor(v)| <= 1e15.
  constexpr float kLimit = 1e15f;
  if (!(std::fabs(x) <= kLimit && std::fabs(y) <= kLimit && std::fabs(z) <= kLimit)) return;
  const std::uint64_t key = ((static_cast<std::uint64_t>(floorToInt(x)) & 0x1FFFFF) << 42) |
                            ((static_cast<std::uint64_t>(floorToInt(y)) & 0x1FFFFF) << 21) |
                            (static_cast<std::uint64_t>(floorToInt(z)) & 0x1FFFFF);
  if (last_voxel_ < 0 || key != last_key_) {
    const std::size_t mask = table_.size() - 1;
    std::size_t h = bucket(key);
    while (table_[h] >= 0 && keys_[table_[h]] != key) h = (h + 1) & mask;
    if (table_[h] < 0) {
      table_[h] = static_cast<std::int32_t>(keys_.size());
      keys_.push_back(key);
      out_.push_back(p);
      counts_.push_back(1);
      if (2 * keys_.size() > table_.size()) grow();
      last_key_ = key;
      last_voxel_ = static_cast<std::int32_t>(keys_.size()) - 1;
      return;
    }
    last_key_ = key;
    last_voxel_ = table_[h];
  }
  out_[last_voxel_].p += p.p;
  ++counts_[last_voxel_];
}

std::vector<LidarPoint> VoxelCentroids::take() {
  for (std::size_t v = 0; v < out_.size(); ++v) out_[v].p /= static_cast<float>(counts_[v]);
  last_voxel_ = -1;
  return std::move(out_);
}

}  // namespace adit::features
