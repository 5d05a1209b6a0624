#include "loop/voxel_filter.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace adit {

std::vector<Eigen::Vector3f> voxelDownsample(const std::vector<Eigen::Vector3f>& points, double voxel) {
  std::vector<Eigen::Vector3f> out;
  if (voxel <= 0.0) {
    for (const auto& p : points)
      if (p.allFinite()) out.push_back(p);
    return out;
  }
  using Key = std::array<long long, 3>;
  std::vector<std::pair<Key, int>> keyed;
  keyed.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) continue;
    Key k;
    for (int d = 0; d < 3; ++d) k[static_cast<std::size_t>(d)] = static_cast<long long>(std::floor(p[d] / voxel));
    keyed.emplace_back(k, static_cast<int>(i));
  }
  std::sort(keyed.begin(), keyed.end());
  for (std::size_t i = 0; i < keyed.size();) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t j = i;
    for (; j < keyed.size() && keyed[j].first == keyed[i].first; ++j)
      sum += points[static_cast<std::size_t>(keyed[j].second)].cast<double>();
    out.push_back((sum / static_cast<double>(j - i)).cast<float>());
    i = j;
  }
  return out;
}

std::size_t VoxelAccumulator::KeyHash::operator()(const Key& k) const {
  std::size_t h = 1469598103934665603ull;
  for (long long v : k) h = (h ^ static_cast<std::size_t>(v)) * 1099511628211ull;
  return h;
}

void VoxelAccumulator::add(const Eigen::Vector3f& p) {
  if (!p.allFinite()) return;
  Key k;
  for (int d = 0; d < 3; ++d) k[static_cast<std::size_t>(d)] = static_cast<long long>(std::floor(p[d] / voxel_));
  Sum& s = cells_[k];
  s.sum += p.cast<double>();
  ++s.count;
}

std::vector<Eigen::Vector3f> VoxelAccumulator::centroids() const {
  std::vector<std::pair<Key, const Sum*>> sorted;
  sorted.reserve(cells_.size());
  for (const auto& kv : cells_) sorted.emplace_back(kv.first, &kv.second);
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Eigen::Vector3f> out;
  out.reserve(sorted.size());
  for (const auto& [key, s] : sorted) out.push_back((s->sum / static_cast<double>(s->count)).cast<float>());
  return out;
}

}  // namespace adit
