// Deterministic voxel-grid downsampling: one centroid per occupied voxel, in voxel-key order.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace adit {

// Non-finite points are dropped; voxel <= 0 only drops non-finite points.
std::vector<Eigen::Vector3f> voxelDownsample(const std::vector<Eigen::Vector3f>& points, double voxel);

}  // namespace adit
