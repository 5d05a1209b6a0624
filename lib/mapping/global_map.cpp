#include "mapping/global_map.hpp"

#include "mapping/downsample.hpp"

#include <algorithm>
#include <cstdint>

namespace adit {

namespace {
constexpr std::size_t kInitialSlots = 1024;
}  // namespace

GlobalMap::GlobalMap(double resolution, std::size_t max_voxels)
    : resolution_(resolution > 0 ? resolution : 0.1), max_voxels_(max_voxels), table_(kInitialSlots, -1) {}

GlobalMap::Cell& GlobalMap::cellOf(const VoxelKey& key) { return cells_[voxelFindOrAdd(table_, cells_, key)]; }

void GlobalMap::insert(const std::vector<Eigen::Vector3f>& sweep_points, const Eigen::Isometry3d& T_world_sweep,
                       double max_range) {
  const Eigen::Isometry3f T = T_world_sweep.cast<float>();
  const float max_sq = static_cast<float>(max_range * max_range);
  std::vector<Eigen::Vector3f>& placed = placed_;
  std::vector<VoxelKey>& keys = keys_;
  placed.clear();
  keys.clear();
  for (const Eigen::Vector3f& p : sweep_points) {
    if (!p.allFinite() || p.squaredNorm() > max_sq) continue;
    placed.push_back(T * p);
    keys.push_back(voxelOf(placed.back(), resolution_));
  }
  // A map of a long run is far beyond the caches: the table slot of the point kAhead on, and the voxel of the
  // point kAhead / 2 on (its slot read by then), are fetched while a point is added; the points are still
  // added in order. Consecutive points of a sweep (scan order) often share a voxel: that lookup is reused.
  constexpr std::size_t kAhead = 16;
  const std::size_t n = placed.size();
  std::size_t last = SIZE_MAX;
  for (std::size_t i = 0; i < n; ++i) {
    if (i + kAhead < n) __builtin_prefetch(&table_[mixedVoxelHash(keys[i + kAhead]) & (table_.size() - 1)]);
    if (i + kAhead / 2 < n) {
      const std::int32_t guess = table_[mixedVoxelHash(keys[i + kAhead / 2]) & (table_.size() - 1)];
      if (guess >= 0) __builtin_prefetch(&cells_[static_cast<std::size_t>(guess)]);
    }
    if (last == SIZE_MAX || !(keys[i] == keys[i - 1])) last = voxelFindOrAdd(table_, cells_, keys[i]);
    Cell& c = cells_[last];
    // A few samples fix the centroid; capping the count keeps the float sum exact to ~1 mm even 1 km out.
    if (c.count >= kMaxSamplesPerCell) continue;
    c.sum += placed[i];
    ++c.count;
  }
  while (max_voxels_ > 0 && cells_.size() > max_voxels_) coarsen();
}

// Doubles the resolution: each voxel's centroid joins its parent voxel, weighted by its samples. Merged in
// key order (not the table's), so the sums, and the map, do not depend on the table's layout.
void GlobalMap::coarsen() {
  std::vector<Cell> sorted = std::move(cells_);
  std::sort(sorted.begin(), sorted.end(), [](const Cell& a, const Cell& b) { return a.key < b.key; });
  cells_ = {};
  table_.assign(kInitialSlots, -1);
  resolution_ *= 2.0;
  ++coarsenings_;
  const auto parent = [](std::int32_t i) { return i >= 0 ? i / 2 : -((-i + 1) / 2); };  // floor(i / 2)
  for (const Cell& cell : sorted) {
    Cell& merged = cellOf(VoxelKey{parent(cell.key.x), parent(cell.key.y), parent(cell.key.z)});
    merged.sum += cell.sum;
    merged.count += cell.count;
    // Keep the sum of at most kMaxSamplesPerCell samples (its float precision), as insert() does.
    if (merged.count > kMaxSamplesPerCell) {
      merged.sum *= static_cast<float>(kMaxSamplesPerCell) / static_cast<float>(merged.count);
      merged.count = kMaxSamplesPerCell;
    }
  }
}

std::vector<Eigen::Vector3f> GlobalMap::points(double voxel_size) const {
  std::vector<std::pair<VoxelKey, Eigen::Vector3f>> keyed;
  keyed.reserve(cells_.size());
  for (const Cell& c : cells_) keyed.emplace_back(c.key, c.sum / static_cast<float>(c.count));
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
