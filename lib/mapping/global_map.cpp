#include "mapping/global_map.hpp"

#include "mapping/downsample.hpp"

#include <algorithm>

namespace adit {

GlobalMap::GlobalMap(double resolution) : resolution_(resolution > 0 ? resolution : 0.1) {}

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
