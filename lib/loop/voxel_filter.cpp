#include "loop/voxel_filter.hpp"

#include "core/hash_mix.hpp"

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
bool packedKey(const Key& k, std::uint64_t& code) {
  code = 0;
  for (const long long v : k) {
    if (v < -kPackedHalfRange || v >= kPackedHalfRange) return false;
    code = (code << 21) | static_cast<std::uint64_t>(v + kPackedHalfRange);
  }
  return true;
}

bool packAll(const std::vector<Eigen::Vector3f>& points, double voxel,
             std::vector<std::pair<std::uint64_t, int>>& packed) {
  packed.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    Key k;
    std::uint64_t code = 0;
    if (!voxelKeyOf(points[i], voxel, k)) continue;
    if (!packedKey(k, code)) return false;
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

namespace {

// FNV-1a over the three indices, its high bits mixed into the low ones that pick the slot.
std::size_t hashOf(const std::array<long long, 3>& k) {
  std::uint64_t h = 1469598103934665603ull;
  for (long long v : k) h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ull;
  return static_cast<std::size_t>(mixHashBits(h));
}

}  // namespace

VoxelAccumulator::VoxelAccumulator(double voxel) : voxel_(voxel), table_(1024, -1) {}

std::size_t VoxelAccumulator::slotOf(const Key& key) const {
  const std::size_t mask = table_.size() - 1;
  std::size_t slot = hashOf(key) & mask;
  while (table_[slot] >= 0 && cells_[static_cast<std::size_t>(table_[slot])].key != key) slot = (slot + 1) & mask;
  return slot;
}

void VoxelAccumulator::grow() {
  table_.assign(table_.size() * 2, -1);
  for (std::size_t i = 0; i < cells_.size(); ++i) table_[slotOf(cells_[i].key)] = static_cast<std::int32_t>(i);
}

void VoxelAccumulator::add(const Eigen::Vector3f& p) {
  Key k;
  if (!voxelKeyOf(p, voxel_, k)) return;
  std::size_t slot = slotOf(k);
  if (table_[slot] < 0) {
    if (2 * (cells_.size() + 1) > table_.size()) {
      grow();
      slot = slotOf(k);
    }
    table_[slot] = static_cast<std::int32_t>(cells_.size());
    cells_.push_back({k});
  }
  Cell& c = cells_[static_cast<std::size_t>(table_[slot])];
  c.sum += p.cast<double>();
  ++c.count;
}

std::vector<Eigen::Vector3f> VoxelAccumulator::centroids() const {
  // Voxel order: the packed key (x, y, z in 21 bits each, which orders like the key) when every voxel has
  // one, else the keys compared through the cells' indices. Keys are unique: the order is the same either way.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> packed;
  packed.reserve(cells_.size());
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    std::uint64_t code = 0;
    if (!packedKey(cells_[i].key, code)) {
      packed = {};
      break;
    }
    packed.emplace_back(code, static_cast<std::uint32_t>(i));
  }
  std::vector<Eigen::Vector3f> out;
  out.reserve(cells_.size());
  const auto centroid = [this, &out](std::uint32_t i) {
    const Cell& c = cells_[i];
    out.push_back((c.sum / static_cast<double>(c.count)).cast<float>());
  };
  if (packed.size() == cells_.size()) {
    std::sort(packed.begin(), packed.end());
    for (const auto& [code, i] : packed) centroid(i);
    return out;
  }
  std::vector<std::uint32_t> order(cells_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
  std::sort(order.begin(), order.end(), [this](std::uint32_t a, std::uint32_t b) { return cells_[a].key < cells_[b].key; });
  for (const std::uint32_t i : order) centroid(i);
  return out;
}

}  // namespace adit
