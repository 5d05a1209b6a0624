// The map saved as map.pcd: every registered sweep folded into a voxel grid of fixed resolution (one
// centroid per voxel). Memory grows with the explored volume, not with time.
#pragma once

#include "mapping/voxel_key.hpp"

#include <Eigen/Geometry>

#include <unordered_map>
#include <vector>

namespace adit {

class GlobalMap {
 public:
  explicit GlobalMap(double resolution);

  // Adds points given in the sweep frame, placed with T_world_sweep; points beyond max_range are skipped.
  void insert(const std::vector<Eigen::Vector3f>& sweep_points, const Eigen::Isometry3d& T_world_sweep,
              double max_range);
  // Centroids downsampled to voxel_size (never finer than the stored resolution), sorted by voxel key.
  std::vector<Eigen::Vector3f> points(double voxel_size) const;
  std::size_t numVoxels() const { return cells_.size(); }

 private:
  struct Cell {
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    std::int32_t count = 0;
  };
  static constexpr std::int32_t kMaxSamplesPerCell = 16;
  double resolution_;
  std::unordered_map<VoxelKey, Cell, VoxelKeyHash> cells_;
};

}  // namespace adit
