// The mapper's local map: points in a voxel hash (KISS-ICP style), updated incrementally every sweep and
// trimmed to a radius around the robot, so nothing is rebuilt per sweep and memory stays bounded.
//
// Determinism: results never depend on hash iteration order. Queries are lookups of the 27 voxels around a
// point, each voxel's points kept in insertion order; removal erases a set that does not depend on order;
// whole-map listings are sorted by voxel key.
//
// The voxels are a dense array found through an open-addressing table (linear probing, power-of-two size, at
// most half full): a query looks up to 27 voxels, and std::unordered_map's prime modulo and node chains made
// those lookups a quarter of the mapper's search time.
#pragma once

#include "mapping/voxel_key.hpp"

#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace adit {

class VoxelMap {
 public:
  // voxel_size: cell edge (m), also the largest exact neighbour-search radius. min_spacing: a new point closer
  // than this to a point of its voxel is dropped (map resolution). max_points_per_voxel bounds density.
  VoxelMap(double voxel_size, double min_spacing, int max_points_per_voxel);

  // Adds the points, each unless closer than min_spacing to a point its voxel held before this call (or, with
  // thin_among_them, also to one added by this call before it) or its voxel is full.
  void insert(const std::vector<Eigen::Vector3d>& points, bool thin_among_them = false);
  // Drops every voxel whose centre is farther than radius from centre.
  void removeFarFrom(const Eigen::Vector3d& centre, double radius);
  // Moves every point by T (a loop-closure correction) and re-hashes.
  void transform(const Eigen::Isometry3d& T);

  // Up to k nearest points within max_distance (<= voxel size for exactness), nearest first.
  std::vector<Eigen::Vector3d> nearest(const Eigen::Vector3d& q, int k, double max_distance) const;
  // The same into `out` (its capacity is reused: no allocation per query in a loop).
  void nearest(const Eigen::Vector3d& q, int k, double max_distance, std::vector<Eigen::Vector3d>& out) const;

  std::vector<Eigen::Vector3d> points() const;  // sorted by voxel key
  std::size_t numPoints() const { return num_points_; }
  std::size_t numVoxels() const { return voxels_.size(); }
  bool empty() const { return num_points_ == 0; }
  double voxelSize() const { return voxel_size_; }

 private:
  struct Voxel {
    VoxelKey key;
    std::vector<Eigen::Vector3d> points;  // insertion order
  };
  static constexpr std::int32_t kEmpty = -1;

  const Voxel* find(const VoxelKey& key) const;
  Voxel& findOrAdd(const VoxelKey& key);
  std::size_t slotOf(const VoxelKey& key) const;  // the key's slot, or the empty slot where it would go
  void eraseSlot(std::size_t slot);

  double voxel_size_, min_spacing_sq_;
  int max_points_per_voxel_;
  std::size_t num_points_ = 0;
  std::vector<Voxel> voxels_;         // dense, any order
  std::vector<std::int32_t> table_;   // slot -> index into voxels_, or kEmpty
};

}  // namespace adit
