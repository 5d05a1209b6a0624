// Voxel downsampling as a streaming accumulator: points go in one by one, one point per occupied voxel comes
// out, in order of first occurrence (deterministic: the hash table is used for lookups only). The point is the
// voxel's centroid, or (keep_measured) the measured point nearest the voxel's centre: a centroid of points on
// a curved surface, or of two rings' points at different depths, lies off the surface, and a registration
// against such points is biased (issue 16: scan-to-scan odometry drifted at rest).
#pragma once

#include "core/types.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

namespace adit::features {

class VoxelCentroids {
 public:
  // leaf: voxel size (m), > 0. expected_points: a hint for the first table size (the table grows as needed).
  VoxelCentroids(float leaf, std::size_t expected_points, bool keep_measured = false);

  // Adds p to its voxel. Points with non-finite or absurd coordinates (a hostile message) have no voxel
  // and are skipped: converting them to integers would be undefined.
  void add(const LidarPoint& p) {
    std::uint64_t key;
    if (!voxelKey(p.p, key)) return;
    if (keep_measured_) {
      keepNearestToCentre(key, p);
      return;
    }
    if (last_voxel_ >= 0 && key == last_key_) {  // inline: the common case
      out_[static_cast<std::size_t>(last_voxel_)].p += p.p;
      ++counts_[static_cast<std::size_t>(last_voxel_)];
      return;
    }
    addToOtherVoxel(key, p);
  }

  // One point per voxel: at the centroid of its points, with the ring / time / intensity of the first; or
  // (keep_measured) the point nearest the voxel's centre, as it was measured.
  std::vector<LidarPoint> take();

 private:
  // floor(v) as an integer, for |v| <= 1e15 (exact: such floats convert to int64 without overflow).
  static std::int64_t floorToInt(float v) {
    const auto t = static_cast<std::int64_t>(v);  // truncation toward zero
    return static_cast<float>(t) > v ? t - 1 : t;
  }
  // Packed integer voxel coordinates (21 bits each); false for NaN / inf / beyond 1e15 leaves. Written so that
  // NaN fails too. A float beyond 2^23 is an integer, so |v| <= 1e15 is |floor(v)| <= 1e15.
  bool voxelKey(const Eigen::Vector3f& p, std::uint64_t& key) const {
    const float x = p.x() * inv_leaf_, y = p.y() * inv_leaf_, z = p.z() * inv_leaf_;
    constexpr float kLimit = 1e15f;
    if (!(std::fabs(x) <= kLimit && std::fabs(y) <= kLimit && std::fabs(z) <= kLimit)) return false;
    key = ((static_cast<std::uint64_t>(floorToInt(x)) & 0x1FFFFF) << 42) |
          ((static_cast<std::uint64_t>(floorToInt(y)) & 0x1FFFFF) << 21) |
          (static_cast<std::uint64_t>(floorToInt(z)) & 0x1FFFFF);
    return true;
  }
  void addToOtherVoxel(std::uint64_t key, const LidarPoint& p);
  // The voxel of key (last_voxel_ updated), or a new one holding p (then `added` is true).
  std::int32_t voxelOf(std::uint64_t key, const LidarPoint& p, bool& added);
  void keepNearestToCentre(std::uint64_t key, const LidarPoint& p);
  // Squared distance of p from its voxel's centre, in leaves.
  float squaredFromCentre(const Eigen::Vector3f& p) const {
    float sq = 0.0f;
    for (int i = 0; i < 3; ++i) {
      const float v = p[i] * inv_leaf_;
      const float d = v - static_cast<float>(floorToInt(v)) - 0.5f;
      sq += d * d;
    }
    return sq;
  }
  void grow();
  std::size_t bucket(std::uint64_t key) const { return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_); }

  float inv_leaf_;
  bool keep_measured_ = false;
  int shift_ = 64;                    // bucket = top bits of the multiplied key
  std::vector<std::int32_t> table_;   // bucket -> voxel index, -1 = empty (open addressing, linear probing)
  std::vector<std::uint64_t> keys_;   // per voxel: packed integer coordinates
  std::vector<LidarPoint> out_;       // per voxel: first point, its position holding the running sum
  std::vector<std::int32_t> counts_;  // per voxel: points summed
  std::vector<float> from_centre_;    // per voxel (keep_measured): squared distance of the kept point
  std::uint64_t last_key_ = 0;        // consecutive points of a ring mostly share a voxel: skip the lookup
  std::int32_t last_voxel_ = -1;
};

}  // namespace adit::features
