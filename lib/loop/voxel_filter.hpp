// Deterministic voxel-grid downsampling: one centroid per occupied voxel, in voxel-key order.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <deque>
#include <vector>

namespace adit {

// Non-finite points are dropped, and points too far out for a voxel index (|p / voxel| >= 2^62: a corrupt
// cloud or pose); voxel <= 0 only drops non-finite points.
std::vector<Eigen::Vector3f> voxelDownsample(const std::vector<Eigen::Vector3f>& points, double voxel);

// The same centroids from points added piece by piece (e.g. keyframe by keyframe), holding one sum per
// voxel instead of every point: the corrected map of a long run without all its points at once. Points
// added in the order voxelDownsample would see them give bit-identical centroids.
//
// The voxels sit in chunked storage found through an open-addressing table (at most half full), ~64 bytes a
// voxel where std::unordered_map's nodes, buckets and allocation headers took ~100, with no allocation per
// voxel; centroids() orders them by a packed 64-bit key where every key fits one (a map within +-2^20 voxels),
// by index otherwise. The 30-minute run's map (~1.5 M voxels of 0.1 m) is the peak of its memory.
class VoxelAccumulator {
 public:
  explicit VoxelAccumulator(double voxel);
  void add(const Eigen::Vector3f& point);  // dropped as by voxelDownsample
  std::vector<Eigen::Vector3f> centroids() const;  // in voxel-key order
  std::size_t size() const { return cells_.size(); }

 private:
  using Key = std::array<long long, 3>;
  struct Cell {
    Key key;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    long long count = 0;
  };
  std::size_t slotOf(const Key& key) const;  // the key's slot, or the empty slot where it would go
  void grow();
  double voxel_;
  std::deque<Cell> cells_;            // in order of their first point; chunked: growing copies nothing
  std::vector<std::int32_t> table_;   // slot -> index into cells_, -1 empty
};

}  // namespace adit
