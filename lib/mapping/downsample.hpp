// Voxel-grid downsampling to centroids, output sorted by voxel key (deterministic order).
#pragma once

#include <Eigen/Core>

#include <vector>

namespace adit {

// One centroid per occupied voxel of edge voxel_size (m); non-finite points are dropped. voxel_size <= 0
// returns the finite input points unchanged.
std::vector<Eigen::Vector3d> voxelDownsample(const std::vector<Eigen::Vector3d>& points, double voxel_size);

}  // namespace adit
