#include "mapping/voxel_map.hpp"

#include <algorithm>
#include <map>

namespace adit {

VoxelMap::VoxelMap(double voxel_size, double min_spacing, int max_points_per_voxel)
    : voxel_size_(voxel_size > 0 ? voxel_size : 1.0),
      min_spacing_sq_(min_spacing * min_spacing),
      max_points_per_voxel_(std::max(1, max_points_per_voxel)) {}

void VoxelMap::insert(const std::vector<Eigen::Vector3d>& points) {
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    auto& cell = voxels_[voxelOf(p, voxel_size_)];
    if (static_cast<int>(cell.size()) >= max_points_per_voxel_) continue;
    const bool crowded = std::any_of(cell.begin(), cell.end(),
                                     [&](const Eigen::Vector3d& o) { return (o - p).squaredNorm() < min_spacing_sq_; });
    if (crowded) continue;
    cell.push_back(p);
    ++num_points_;
  }
}

void VoxelMap::removeFarFrom(const Eigen::Vector3d& centre, double radius) {
  const double r_sq = radius * radius;
  for (auto it = voxels_.begin(); it != voxels_.end();) {
    const Eigen::Vector3d c((it->first.x + 0.5) * voxel_size_, (it->first.y + 0.5) * voxel_size_,
                            (it->first.z + 0.5) * voxel_size_);
    if ((c - centre).squaredNorm() > r_sq) {
      num_points_ -= it->second.size();
      it = voxels_.erase(it);
    } else {
      ++it;
    }
  }
}

void VoxelMap::transform(const Eigen::Isometry3d& T) {
  std::vector<Eigen::Vector3d> moved = points();
  for (Eigen::Vector3d& p : moved) p = T * p;
  voxels_.clear();
  num_points_ = 0;
  insert(moved);
}

std::vector<Eigen::Vector3d> VoxelMap::nearest(const Eigen::Vector3d& q, int k, double max_distance) const {
  std::vector<std::pair<double, Eigen::Vector3d>> best;  // ascending by distance, at most k
  if (k <= 0 || !q.allFinite()) return {};
  best.reserve(static_cast<std::size_t>(k) + 1);
  const double max_sq = max_distance * max_distance;
  const VoxelKey c = voxelOf(q, voxel_size_);
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = voxels_.find({c.x + dx, c.y + dy, c.z + dz});
        if (it == voxels_.end()) continue;
        for (const Eigen::Vector3d& p : it->second) {
          const double sq = (p - q).squaredNorm();
          if (sq >= max_sq || (static_cast<int>(best.size()) == k && sq >= best.back().first)) continue;
          // Insertion keeps the order stable for equal distances (first found wins): deterministic.
          auto pos = std::upper_bound(best.begin(), best.end(), sq,
                                      [](double v, const auto& e) { return v < e.first; });
          best.insert(pos, {sq, p});
          if (static_cast<int>(best.size()) > k) best.pop_back();
        }
      }
  std::vector<Eigen::Vector3d> out;
  out.reserve(best.size());
  for (const auto& e : best) out.push_back(e.second);
  return out;
}

std::vector<Eigen::Vector3d> VoxelMap::points() const {
  std::map<VoxelKey, const std::vector<Eigen::Vector3d>*> sorted;
  for (const auto& kv : voxels_) sorted.emplace(kv.first, &kv.second);
  std::vector<Eigen::Vector3d> out;
  out.reserve(num_points_);
  for (const auto& kv : sorted) out.insert(out.end(), kv.second->begin(), kv.second->end());
  return out;
}

}  // namespace adit
