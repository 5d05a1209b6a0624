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
std::uint64_t hashOf(const std::array<long long, 3>& k) {
  std::uint64_t h = 1469598103934665603ull;
  for (long long v : k) h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ull;
  return mixHashBits(h);
}

}  // namespace

VoxelAccumulator::VoxelAccumulator(double voxel) : voxel_(voxel), table_(1024) {}

std::size_t VoxelAccumulator::slotOf(const Key& key, std::uint64_t hash) const {
  const std::size_t mask = table_.size() - 1;
  const auto tag = static_cast<std::uint32_t>(hash >> 32);
  for (std::size_t slot = hash & mask;; slot = (slot + 1) & mask) {
    const Slot& s = table_[slot];
    if (s.index < 0) return slot;
    if (s.tag != tag) continue;
    const Key& k = cell(static_cast<std::size_t>(s.index)).key;
    if (k[0] == key[0] && k[1] == key[1] && k[2] == key[2]) return slot;
  }
}

void VoxelAccumulator::grow() {
  table_.assign(table_.size() * 2, Slot{});
  constexpr std::size_t kAhead = 16;  // the slot of voxel i + kAhead is fetched while voxel i is placed
  std::array<std::uint64_t, kAhead> hashes{};
  for (std::size_t i = 0; i < size_ + kAhead; ++i) {
    std::uint64_t& hash = hashes[i % kAhead];  // voxel i - kAhead's, then voxel i's
    if (i >= kAhead) {
      const std::size_t v = i - kAhead;
      table_[slotOf(cell(v).key, hash)] = {static_cast<std::uint32_t>(hash >> 32), static_cast<std::int32_t>(v)};
    }
    if (i < size_) {
      hash = hashOf(cell(i).key);
      __builtin_prefetch(&table_[hash & (table_.size() - 1)]);
    }
  }
}

void VoxelAccumulator::addKeyed(const Key& k, std::uint64_t hash, const Eigen::Vector3f& p) {
  std::size_t slot = slotOf(k, hash);
  if (table_[slot].index < 0) {
    if (2 * (size_ + 1) > table_.size()) {
      grow();
      slot = slotOf(k, hash);
    }
    if ((size_ >> kChunkBits) == chunks_.size()) chunks_.push_back(std::make_unique<Cell[]>(std::size_t{1} << kChunkBits));
    cell(size_).key = k;
    table_[slot] = {static_cast<std::uint32_t>(hash >> 32), static_cast<std::int32_t>(size_)};
    ++size_;
  }
  Cell& c = cell(static_cast<std::size_t>(table_[slot].index));
  c.sum += p.cast<double>();
  ++c.count;
}

void VoxelAccumulator::add(const Eigen::Vector3f& p) {
  Key k;
  if (voxelKeyOf(p, voxel_, k)) addKeyed(k, hashOf(k), p);
}

void VoxelAccumulator::add(const std::vector<Eigen::Vector3f>& points) {
  // A map of millions of voxels is far beyond the caches: each point's slot and voxel are a miss each. Point
  // i + kAhead's slot is fetched, and point i + kAhead / 2's voxel (its slot read by then), before point i is
  // added; the points are still added one by one in order, so the sums are those of add(point).
  constexpr std::size_t kAhead = 16;
  struct Pending {
    Key key;
    std::uint64_t hash = 0;
    bool valid = false;
  };
  std::array<Pending, kAhead> ring;
  const std::size_t n = points.size();
  for (std::size_t i = 0; i < n + kAhead; ++i) {
    Pending& entry = ring[i % kAhead];  // point i - kAhead's, then point i's
    if (i >= kAhead && entry.valid) addKeyed(entry.key, entry.hash, points[i - kAhead]);
    entry.valid = i < n && voxelKeyOf(points[i], voxel_, entry.key);
    if (entry.valid) {
      entry.hash = hashOf(entry.key);
      __builtin_prefetch(&table_[entry.hash & (table_.size() - 1)]);
    }
    const Pending& middle = ring[(i + kAhead / 2) % kAhead];  // point i - kAhead / 2's
    if (i >= kAhead / 2 && middle.valid) {
      const Slot& s = table_[middle.hash & (table_.size() - 1)];
      if (s.index >= 0 && s.tag == static_cast<std::uint32_t>(middle.hash >> 32))
        __builtin_prefetch(&cell(static_cast<std::size_t>(s.index)));
    }
  }
}

std::vector<Eigen::Vector3f> VoxelAccumulator::centroids() const {
  // Voxel order: the packed key (x, y, z in 21 bits each, which orders like the key) when every voxel has
  // one, else the keys compared through the cells' indices. Keys are unique: the order is the same either way.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> packed;
  packed.reserve(size_);
  for (std::size_t i = 0; i < size_; ++i) {
    std::uint64_t code = 0;
    if (!packedKey(cell(i).key, code)) {
      packed = {};
      break;
    }
    packed.emplace_back(code, static_cast<std::uint32_t>(i));
  }
  std::vector<Eigen::Vector3f> out;
  out.reserve(size_);
  const auto centroid = [this, &out](std::uint32_t i) {
    const Cell& c = cell(i);
    out.push_back((c.sum / static_cast<double>(c.count)).cast<float>());
  };
  if (packed.size() == size_) {
    std::sort(packed.begin(), packed.end());
    constexpr std::size_t kAhead = 8;  // voxels in key order are scattered over the cells: fetch ahead
    for (std::size_t j = 0; j < packed.size(); ++j) {
      if (j + kAhead < packed.size()) __builtin_prefetch(&cell(packed[j + kAhead].second));
      centroid(packed[j].second);
    }
    return out;
  }
  std::vector<std::uint32_t> order(size_);
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
  std::sort(order.begin(), order.end(), [this](std::uint32_t a, std::uint32_t b) { return cell(a).key < cell(b).key; });
  for (const std::uint32_t i : order) centroid(i);
  return out;
}

}  // namespace adit
