// One sweep's feature points indexed for A-LOAM-style correspondence search: a KD-tree over all points, and
// each ring's points in azimuth order, so "nearest points on a neighbouring ring" is a short walk outward
// from the query's azimuth rather than a search of a tree built for every ring of every sweep.
#pragma once

#include "core/types.hpp"
#include "registration/kdtree.hpp"

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
  // A query point with what the ring queries need of it (its azimuth, its horizontal range), for asking
  // several rings about the same point.
  struct RingQuery {
    explicit RingQuery(const Eigen::Vector3d& query);
    Eigen::Vector3f q;
    float h, azimuth;
    bool finite;
  };
  // The ring queries are exact as the tree's (squared distances in float, below the bound); among points at
  // exactly the same distance the one nearer the query's azimuth comes first.
  int nearestInRing(int ring, const RingQuery& q, double max_sq_distance, int exclude) const;
  int nearestInRing(int ring, const Eigen::Vector3d& q, double max_sq_distance, int exclude) const {
    return nearestInRing(ring, RingQuery(q), max_sq_distance, exclude);
  }
  // Up to k nearest points of one ring, nearest first.
  void nearestKInRing(int ring, const RingQuery& q, int k, double max_sq_distance, std::vector<int>& out) const;
  std::vector<int> nearestKInRing(int ring, const Eigen::Vector3d& q, int k, double max_sq_distance) const {
    std::vector<int> out;
    nearestKInRing(ring, RingQuery(q), k, max_sq_distance, out);
    return out;
  }
  // Nearest over rings ring-window .. ring+window, excluding `ring` itself.
  int nearestInNeighbourRings(int ring, int window, const Eigen::Vector3d& q, double max_sq_distance) const;

  const Eigen::Vector3d& point(int i) const { return all_.point(i); }
  int ring(int i) const { return rings_[static_cast<std::size_t>(i)]; }
  std::size_t size() const { return all_.size(); }

 private:
  // A ring's points by ascending azimuth (atan2, in [-pi, pi]).
  struct Ring {
    std::vector<float> azimuth;
    std::vector<Eigen::Vector3f> xyz;  // float, as the tree compares them
    std::vector<int> to_global;        // position -> index in all_
  };
  // Up to k nearest of `ring` below max_sq, skipping global index `exclude`, into dists / indices (global).
  int searchRing(const Ring& ring, const RingQuery& q, int k, float max_sq, int exclude, float* dists,
                 int* indices) const;
  const Ring* findRing(int ring) const;

  KdTree3 all_;
  std::vector<int> rings_;
  std::vector<int> ring_numbers_;  // the rings that hold points, ascending
  std::vector<Ring> by_ring_;      // the same order
};

}  // namespace adit
