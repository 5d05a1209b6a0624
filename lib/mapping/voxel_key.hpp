// Integer voxel coordinates and their hash, shared by the local and global maps.
#pragma once

#include "core/hash_mix.hpp"

#include <Eigen/Core>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <utility>
#include <vector>

namespace adit {

struct VoxelKey {
  std::int32_t x = 0, y = 0, z = 0;
  bool operator==(const VoxelKey& o) const { return x == o.x && y == o.y && z == o.z; }
  bool operator<(const VoxelKey& o) const { return std::tie(x, y, z) < std::tie(o.x, o.y, o.z); }
};

struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& k) const {
    // Teschner et al. 2003 spatial hash primes.
    return static_cast<std::size_t>((static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.x)) * 73856093u) ^
                                    (static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.y)) * 19349669u) ^
                                    (static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.z)) * 83492791u));
  }
};

// The spatial hash mixed so that its low bits, which pick a slot of an open-addressing table, depend on
// every bit of the key.
inline std::size_t mixedVoxelHash(const VoxelKey& key) { return static_cast<std::size_t>(mixHashBits(VoxelKeyHash{}(key))); }

// The open-addressing tables of the mapper's voxel grids (local map, global map, thinning): a power-of-two
// table of indices into `cells` (each with a `key`), -1 empty, linear probing. The slot holding key, or the
// empty slot where it would go.
template <class Cells>
std::size_t voxelSlot(const std::vector<std::int32_t>& table, const Cells& cells, const VoxelKey& key) {
  const std::size_t mask = table.size() - 1;
  std::size_t slot = mixedVoxelHash(key) & mask;
  while (table[slot] >= 0 && !(cells[static_cast<std::size_t>(table[slot])].key == key)) slot = (slot + 1) & mask;
  return slot;
}

// The index of key's cell in `cells`, a cell made from the key alone appended if there is none. The table
// doubles (and is refilled in the cells' order) before it would be more than half full.
template <class Cell>
std::size_t voxelFindOrAdd(std::vector<std::int32_t>& table, std::vector<Cell>& cells, const VoxelKey& key) {
  std::size_t slot = voxelSlot(table, cells, key);
  if (table[slot] >= 0) return static_cast<std::size_t>(table[slot]);
  if (2 * (cells.size() + 1) > table.size()) {
    table.assign(table.size() * 2, -1);
    for (std::size_t i = 0; i < cells.size(); ++i) table[voxelSlot(table, cells, cells[i].key)] = static_cast<std::int32_t>(i);
    slot = voxelSlot(table, cells, key);
  }
  table[slot] = static_cast<std::int32_t>(cells.size());
  Cell cell{};
  cell.key = key;
  cells.push_back(std::move(cell));
  return cells.size() - 1;
}

// Voxel index of one coordinate, clamped so that the cast cannot overflow (a tiny voxel or a far point; a
// NaN lands in voxel 0) and a neighbour index (+-1) still fits in 32 bits.
inline std::int32_t voxelIndex(double coordinate, double voxel_size) {
  const double i = std::floor(coordinate / voxel_size);
  constexpr double kLimit = 2147483646.0;
  return i >= -kLimit && i <= kLimit ? static_cast<std::int32_t>(i) : (i > 0 ? 2147483646 : (i < 0 ? -2147483646 : 0));
}

template <class Vec>
inline VoxelKey voxelOf(const Vec& p, double voxel_size) {
  return {voxelIndex(p.x(), voxel_size), voxelIndex(p.y(), voxel_size), voxelIndex(p.z(), voxel_size)};
}

}  // namespace adit
