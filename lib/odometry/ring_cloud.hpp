// One sweep's feature points indexed for A-LOAM-style correspondence search: a KD-tree over all points and
// one per ring, so "nearest point on a neighbouring ring" is a tree query rather than a linear scan.
#pragma once

#include "core/types.hpp"
#include "registration/kdtree.hpp"

#include <map>
#include <vector>

namespace adit {

class RingIndexedCloud {
 public:
  RingIndexedCloud() = default;
  // Non-finite points are dropped.
  explicit RingIndexedCloud(const std::vector<LidarPoint>& points);

  // Indices below refer to point(i) / ring(i); -1 means none within sqrt(max_sq_distance).
  int nearest(const Eigen::Vector3d& q, double max_sq_distance) const;
  // The k-nearest queries write into `out` (its capacity is reused: no allocation per query in a loop).
  void nearestK(const Eigen::Vector3d& q, int k, double max_sq_distance, std::vector<int>& out) const {
    all_.nearestK(q, k, max_sq_distance, out);
  }
  std::vector<int> nearestK(const Eigen::Vector3d& q, int k, double max_sq_distance) const {
    return all_.nearestK(q, k, max_sq_distance);
  }
  int nearestInRing(int ring, const Eigen::Vector3d& q, double max_sq_distance, int exclude) const;
  // Up to k nearest points of one ring, nearest first.
  void nearestKInRing(int ring, const Eigen::Vector3d& q, int k, double max_sq_distance, std::vector<int>& out) const;
  std::vector<int> nearestKInRing(int ring, const Eigen::Vector3d& q, int k, double max_sq_distance) const {
    std::vector<int> out;
    nearestKInRing(ring, q, k, max_sq_distance, out);
    return out;
  }
  // Nearest over rings ring-window .. ring+window, excluding `ring` itself.
  int nearestInNeighbourRings(int ring, int window, const Eigen::Vector3d& q, double max_sq_distance) const;

  const Eigen::Vector3d& point(int i) const { return all_.point(i); }
  int ring(int i) const { return rings_[static_cast<std::size_t>(i)]; }
  std::size_t size() const { return all_.size(); }

 private:
  struct Ring {
    KdTree3 tree;
    std::vector<int> to_global;  // tree index -> index in all_
  };
  KdTree3 all_;
  std::vector<int> rings_;
  std::vector<int> index_in_ring_;  // index in all_ -> index in its ring's tree
  std::map<int, Ring> by_ring_;
};

}  // namespace adit
