// Integer voxel coordinates and their hash, shared by the local and global maps.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <tuple>

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

template <class Vec>
inline VoxelKey voxelOf(const Vec& p, double voxel_size) {
  return {static_cast<std::int32_t>(std::floor(p.x() / voxel_size)),
          static_cast<std::int32_t>(std::floor(p.y() / voxel_size)),
          static_cast<std::int32_t>(std::floor(p.z() / voxel_size))};
}

}  // namespace adit
