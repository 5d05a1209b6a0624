// Deterministic voxel-grid downsampling: one centroid per occupied voxel, in voxel-key order.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace adit {

// Non-finite points are dropped, and points too far out for a voxel index (|p / voxel| >= 2^62: a corrupt
// cloud or pose); voxel <= 0 only drops non-finite points.
std::vector<Eigen::Vector3f> voxelDownsample(const std::vector<Eigen::Vector3f>& points, double voxel);

// The same centroids from points added piece by piece (e.g. keyframe by keyframe), holding one sum per
// voxel instead of every point: the corrected map of a long run without all its points at once. Points
// added in the order voxelDownsample would see them give bit-identical centroids.
//
// The voxels sit in chunks of 4,096 found through an open-addressing table (at most half full) whose slots
// carry 32 bits of the key's hash beside the voxel's index: a probe compares the tag in the table and reads a
// voxel only where the tag matches, so a point costs about one cache miss in the table and one in its voxel
// (the map of a run's end is millions of voxels, far beyond the caches). ~72 bytes a voxel, no allocation per
// voxel; centroids() orders them by a packed 64-bit key where every key fits one (a map within +-2^20
// voxels), by index otherwise. The 30-minute run's map (~1.5 M voxels of 0.1 m) is the peak of its memory.
class VoxelAccumulator {
 public:
  explicit VoxelAccumulator(double voxel);
  void add(const Eigen::Vector3f& point);  // dropped as by voxelDownsample
  // The same as adding each point in turn (the same sums, bit for bit), with the table slots and voxels of the
  // points a little ahead fetched into the cache while the current one is added.
  void add(const std::vector<Eigen::Vector3f>& points);
  std::vector<Eigen::Vector3f> centroids() const;  // in voxel-key order
  std::size_t size() const { return size_; }

 private:
  using Key = std::array<long long, 3>;
  struct Cell {
    Key key;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    long long count = 0;
  };
  struct Slot {
    std::uint32_t tag = 0;    // the hash's high 32 bits
    std::int32_t index = -1;  // into the cells, -1 empty
  };
  static constexpr int kChunkBits = 12;
  Cell& cell(std::size_t i) { return chunks_[i >> kChunkBits][i & ((std::size_t{1} << kChunkBits) - 1)]; }
  const Cell& cell(std::size_t i) const { return chunks_[i >> kChunkBits][i & ((std::size_t{1} << kChunkBits) - 1)]; }
  // The key's slot, or the empty slot where it would go.
  std::size_t slotOf(const Key& key, std::uint64_t hash) const;
  void grow();
  void addKeyed(const Key& key, std::uint64_t hash, const Eigen::Vector3f& p);
  double voxel_;
  std::size_t size_ = 0;
  std::vector<std::unique_ptr<Cell[]>> chunks_;  // cells in order of their first point; growing copies none
  std::vector<Slot> table_;
};

}  // namespace adit
