// Deterministic voxel-grid downsampling: one centroid per occupied voxel, in voxel-key order.
#pragma once

#include <Eigen/Core>

#include <array>
#include <unordered_map>
#include <vector>

namespace adit {

// Non-finite points are dropped, and points too far out for a voxel index (|p / voxel| >= 2^62: a corrupt
// cloud or pose); voxel <= 0 only drops non-finite points.
std::vector<Eigen::Vector3f> voxelDownsample(const std::vector<Eigen::Vector3f>& points, double voxel);

// The same centroids from points added piece by piece (e.g. keyframe by keyframe), holding one sum per
// voxel instead of every point: the corrected map of a long run without all its points at once. Points
// added in the order voxelDownsample would see them give bit-identical centroids.
class VoxelAccumulator {
 public:
  explicit VoxelAccumulator(double voxel) : voxel_(voxel) {}
  void add(const Eigen::Vector3f& point);  // dropped as by voxelDownsample
  std::vector<Eigen::Vector3f> centroids() const;  // in voxel-key order

 private:
  using Key = std::array<long long, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const;
  };
  struct Sum {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    long long count = 0;
  };
  double voxel_;
  std::unordered_map<Key, Sum, KeyHash> cells_;
};

}  // namespace adit
