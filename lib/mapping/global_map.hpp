// The mapper's own map.pcd (replay without the loop closer): every registered sweep folded into a voxel
// grid (one centroid per voxel). Memory grows with the explored surface, so it is bounded: when it would
// hold more than max_voxels voxels, the grid's resolution doubles (eight voxels merge into one) until it
// fits again. A long run thus keeps its whole extent at a coarser resolution, never loses a region, and
// never holds more than max_voxels voxels (28 bytes each, and 8-16 of table).
//
// The voxels sit in one array in order of their first point, found through an open-addressing table (linear
// probing, at most half full): std::unordered_map's node per voxel made its lookups ~40 % of the mapper's time
// on a 64-beam sweep (bench_odometry). Nothing depends on the table's layout: coarsening merges and points()
// lists the voxels in key order.
#pragma once

#include "mapping/voxel_key.hpp"

#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace adit {

class GlobalMap {
 public:
  // max_voxels 0: unbounded.
  explicit GlobalMap(double resolution, std::size_t max_voxels = 0);

  // Adds points given in the sweep frame, placed with T_world_sweep; points beyond max_range are skipped.
  void insert(const std::vector<Eigen::Vector3f>& sweep_points, const Eigen::Isometry3d& T_world_sweep,
              double max_range);
  // Centroids downsampled to voxel_size (never finer than the stored resolution), sorted by voxel key.
  std::vector<Eigen::Vector3f> points(double voxel_size) const;
  std::size_t numVoxels() const { return cells_.size(); }
  double resolution() const { return resolution_; }
  int coarsenings() const { return coarsenings_; }  // times the resolution doubled to stay within the bound

 private:
  struct Cell {
    VoxelKey key;
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    std::int32_t count = 0;
  };
  Cell& cellOf(const VoxelKey& key);  // found, or added empty
  void coarsen();
  static constexpr std::int32_t kMaxSamplesPerCell = 16;
  double resolution_;
  std::size_t max_voxels_;
  int coarsenings_ = 0;
  std::vector<Cell> cells_;          // in order of their first point
  std::vector<std::int32_t> table_;  // slot -> index into cells_, -1 empty
  std::vector<Eigen::Vector3f> placed_;  // insert()'s sweep in the world and its keys (kept: no allocation a sweep)
  std::vector<VoxelKey> keys_;
};

}  // namespace adit
