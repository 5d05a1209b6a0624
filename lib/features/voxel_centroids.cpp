#include "features/voxel_centroids.hpp"

#include <cmath>

namespace adit::features {

VoxelCentroids::VoxelCentroids(float leaf, std::size_t expected_points, bool keep_measured)
    : inv_leaf_(1.0f / leaf), keep_measured_(keep_measured) {
  // Room for every point in its own voxel at load <= 1/2, so the table never grows: a 16-beam sweep thinned to
  // 0.1 m keeps most of its points (a voxel of a sparse ring holds one or two), and growing the table and the
  // arrays twice on the way was a sixth of the thinning's time (bench_features BM_MapCloudVoxel16Beam).
  std::size_t capacity = 64;
  shift_ = 58;
  while (capacity < 2 * expected_points) {
    capacity <<= 1;
    --shift_;
  }
  table_.assign(capacity, -1);
  const std::size_t voxels = expected_points + 16;
  keys_.reserve(voxels);
  out_.reserve(voxels);
  counts_.reserve(voxels);
  if (keep_measured_) from_centre_.reserve(voxels);
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

std::int32_t VoxelCentroids::voxelOf(std::uint64_t key, const LidarPoint& p, bool& added) {
  const std::size_t mask = table_.size() - 1;
  std::size_t h = bucket(key);
  while (table_[h] >= 0 && keys_[static_cast<std::size_t>(table_[h])] != key) h = (h + 1) & mask;
  last_key_ = key;
  added = table_[h] < 0;
  if (!added) return last_voxel_ = table_[h];
  last_voxel_ = static_cast<std::int32_t>(keys_.size());
  table_[h] = last_voxel_;
  keys_.push_back(key);
  out_.push_back(p);
  counts_.push_back(1);
  if (2 * keys_.size() > table_.size()) grow();
  return last_voxel_;
}

void VoxelCentroids::addToOtherVoxel(std::uint64_t key, const LidarPoint& p) {
  bool added = false;
  const auto v = static_cast<std::size_t>(voxelOf(key, p, added));
  if (added) return;
  out_[v].p += p.p;
  ++counts_[v];
}

void VoxelCentroids::keepNearestToCentre(std::uint64_t key, const LidarPoint& p) {
  bool added = false;
  const auto v = static_cast<std::size_t>(last_voxel_ >= 0 && key == last_key_ ? last_voxel_ : voxelOf(key, p, added));
  const float sq = squaredFromCentre(p.p);
  if (added) {
    from_centre_.push_back(sq);
  } else if (sq < from_centre_[v]) {  // ties keep the first: deterministic
    out_[v] = p;
    from_centre_[v] = sq;
  }
}

std::vector<LidarPoint> VoxelCentroids::take() {
  if (!keep_measured_)
    for (std::size_t v = 0; v < out_.size(); ++v) out_[v].p /= static_cast<float>(counts_[v]);
  last_voxel_ = -1;
  return std::move(out_);
}

}  // namespace adit::features
