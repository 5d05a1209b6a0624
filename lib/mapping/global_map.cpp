#include "mapping/global_map.hpp"

#include "mapping/downsample.hpp"

#include <algorithm>

namespace adit {

GlobalMap::GlobalMap(double resolution, std::size_t max_voxels)
    : resolution_(resolution > 0 ? resolution : 0.1), max_voxels_(max_voxels) {}

void GlobalMap::insert(const std::vector<Eigen::Vector3f>& sweep_points, const Eigen::Isometry3d& T_world_sweep,
                       double max_range) {
  const Eigen::Isometry3f T = T_world_sweep.cast<float>();
  const float max_sq = static_cast<float>(max_range * max_range);
  // Consecutive points of a sweep (scan order) often share a cell: reuse the last lookup (element pointers
  // of an unordered_map stay valid across inserts).
  VoxelKey last_key;
  Cell* last = nullptr;
  for (const Eigen::Vector3f& p : sweep_points) {
    if (!p.allFinite() || p.squaredNorm() > max_sq) continue;
    const Eigen::Vector3f w = T * p;
    const VoxelKey key = voxelOf(w, resolution_);
    if (last == nullptr || !(key == last_key)) {
      last = &cells_[key];
      last_key = key;
    }
    Cell& c = *last;
    // A few samples fix the centroid; capping the count keeps the float sum exact to ~1 mm even 1 km out.
    if (c.count >= kMaxSamplesPerCell) continue;
    c.sum += w;
    ++c.count;
  }
  while (max_voxels_ > 0 && cells_.size() > max_voxels_) coarsen();
}

// Doubles the resolution: each voxel's centroid joins its parent voxel, weighted by its samples. Merged in
// key order (not the hash table's), so the sums, and the map, do not depend on the table's layout.
void GlobalMap::coarsen() {
  std::vector<std::pair<VoxelKey, Cell>> sorted(cells_.begin(), cells_.end());
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  cells_.clear();
  resolution_ *= 2.0;
  ++coarsenings_;
  const auto parent = [](std::int32_t i) { return i >= 0 ? i / 2 : -((-i + 1) / 2); };  // floor(i / 2)
  for (const auto& [key, cell] : sorted) {
    Cell& merged = cells_[VoxelKey{parent(key.x), parent(key.y), parent(key.z)}];
    merged.sum += cell.sum;
    merged.count += cell.count;
    // Keep the sum of at most kMaxSamplesPerCell samples (its float precision), as insert() does.
    if (merged.count > kMaxSamplesPerCell) {
      merged.sum *= static_cast<float>(kMaxSamplesPerCell) / static_cast<float>(merged.count);
      merged.count = kMaxSamplesPerCell;
    }
  }
  cells_.rehash(0);  // give back the buckets of the finer grid
}

std::vector<Eigen::Vector3f> GlobalMap::points(double voxel_size) const {
  std::vector<std::pair<VoxelKey, Eigen::Vector3f>> keyed;
  keyed.reserve(cells_.size());
  for (const auto& kv : cells_) keyed.emplace_back(kv.first, kv.second.sum / static_cast<float>(kv.second.count));
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Eigen::Vector3f> out;
  out.reserve(keyed.size());
  if (voxel_size <= resolution_) {
    for (const auto& kv : keyed) out.push_back(kv.second);
    return out;
  }
  std::vector<Eigen::Vector3d> fine;
  fine.reserve(keyed.size());
  for (const auto& kv : keyed) fine.push_back(kv.second.cast<double>());
  for (const Eigen::Vector3d& p : voxelDownsample(fine, voxel_size)) out.push_back(p.cast<float>());
  return out;
}

}  // namespace adit
