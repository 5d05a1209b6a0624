#include "mapping/downsample.hpp"

#include "mapping/voxel_key.hpp"

#include <algorithm>
#include <unordered_map>

namespace adit {

std::vector<Eigen::Vector3d> voxelDownsample(const std::vector<Eigen::Vector3d>& points, double voxel_size) {
  std::vector<Eigen::Vector3d> out;
  if (voxel_size <= 0) {
    std::copy_if(points.begin(), points.end(), std::back_inserter(out),
                 [](const Eigen::Vector3d& p) { return p.allFinite(); });
    return out;
  }
  struct Sum {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
  };
  std::unordered_map<VoxelKey, Sum, VoxelKeyHash> cells;
  cells.reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    Sum& s = cells[voxelOf(p, voxel_size)];
    s.sum += p;  // points arrive in input order per voxel: the sum is deterministic
    ++s.count;
  }
  std::vector<std::pair<VoxelKey, Eigen::Vector3d>> keyed;
  keyed.reserve(cells.size());
  for (const auto& kv : cells) keyed.emplace_back(kv.first, kv.second.sum / kv.second.count);
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  out.reserve(keyed.size());
  for (const auto& kv : keyed) out.push_back(kv.second);
  return out;
}

}  // namespace adit
