#include "loop/voxel_filter.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

namespace adit {
namespace {

using Key = std::array<long long, 3>;

// The voxel holding p, or false for a point that has none: non-finite, or so far out (|p / voxel| >= 2^62, a
// corrupt cloud or pose, nowhere near a map) that its index does not fit the key. Such points are dropped.
bool voxelKeyOf(const Eigen::Vector3f& p, double voxel, Key& key) {
  constexpr double kLimit = 4.611686018427388e18;  // 2^62
  for (int d = 0; d < 3; ++d) {
    const double i = std::floor(static_cast<double>(p[d]) / voxel);
    if (!(i > -kLimit && i < kLimit)) return false;  // NaN fails too
    key[static_cast<std::size_t>(d)] = static_cast<long long>(i);
  }
  return true;
}

// Centroids of `keyed` (voxel key and point index) once sorted by key then index: the points of a voxel summed
// in index order, the voxels in key order.
template <class Keyed>
std::vector<Eigen::Vector3f> centroidsOfSorted(const std::vector<Eigen::Vector3f>& points, std::vector<Keyed>& keyed) {
  std::sort(keyed.begin(), keyed.end());
  std::vector<Eigen::Vector3f> out;
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

// Voxel indices within +-2^20 (+-262 km at 0.25 m) packed into one integer that orders like the key (x, y, z):
// half the bytes to sort and one comparison instead of three. False if a point is beyond that.
constexpr long long kPackedHalfRange = 1LL << 20;
bool packAll(const std::vector<Eigen::Vector3f>& points, double voxel,
             std::vector<std::pair<std::uint64_t, int>>& packed) {
  packed.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    Key k;
    if (!voxelKeyOf(points[i], voxel, k)) continue;
    std::uint64_t code = 0;
    for (const long long v : k) {
      if (v < -kPackedHalfRange || v >= kPackedHalfRange) return false;
      code = (code << 21) | static_cast<std::uint64_t>(v + kPackedHalfRange);
    }
    packed.emplace_back(code, static_cast<int>(i));
  }
  return true;
}

}  // namespace

std::vector<Eigen::Vector3f> voxelDownsample(const std::vector<Eigen::Vector3f>& points, double voxel) {
  if (voxel <= 0.0) {
    std::vector<Eigen::Vector3f> out;
    for (const auto& p : points)
      if (p.allFinite()) out.push_back(p);
    return out;
  }
  std::vector<std::pair<std::uint64_t, int>> packed;
  if (packAll(points, voxel, packed))
    return centroidsOfSorted(points, packed);
  std::vector<std::pair<Key, int>> keyed;
  keyed.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    Key k;
    if (voxelKeyOf(points[i], voxel, k)) keyed.emplace_back(k, static_cast<int>(i));
  }
  return centroidsOfSorted(points, keyed);
}

std::size_t VoxelAccumulator::KeyHash::operator()(const Key& k) const {
  std::size_t h = 1469598103934665603ull;
  for (long long v : k) h = (h ^ static_cast<std::size_t>(v)) * 1099511628211ull;
  return h;
}

void VoxelAccumulator::add(const Eigen::Vector3f& p) {
  Key k;
  if (!voxelKeyOf(p, voxel_, k)) return;
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
