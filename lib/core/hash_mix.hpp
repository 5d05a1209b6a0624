// The last step of a hash whose low bits pick a slot of an open-addressing table (the voxel tables of the
// mapper and of the corrected map): a multiply-xorshift that carries every bit of the input into the low ones.
#pragma once

#include <cstdint>

namespace adit {

inline std::uint64_t mixHashBits(std::uint64_t h) {
  h ^= h >> 31;
  h *= 0xbf58476d1ce4e5b9ULL;
  h ^= h >> 29;
  return h;
}

}  // namespace adit
