// A static 3-D KD-tree (nanoflann, leaves of up to 16 points) for nearest-neighbour queries: one sweep's
// feature points in odometry, a keyframe submap in loop verification.
//
// The tree searches a single-precision copy of the points (they come from float sweeps and clouds; half the
// bytes per visited point made odometry's searches ~10 % cheaper), so distances compare in float; point()
// returns the points as given. Built once (median splits, no randomness) and queried a few thousand times.
// Deterministic: equal distances keep the order in which the search met them, which depends only on the
// points. Copies share the (immutable) index.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace adit {

// What a nearest-point search learnt about one query, so that the next search of the same query, moved a
// little, can be answered without the tree (an ICP's later iterations move its points by millimetres). If
// the nearest point was at distance d1 and every other at least d2, a query moved by less than (d2 - d1) / 2
// still has that point nearest (triangle inequality): the kept answer is the tree's, not an approximation.
struct NearestMemo {
  Eigen::Vector3f at = Eigen::Vector3f::Zero();  // where the query was searched (float, as the tree compares)
  int index = -1;                                // its nearest point; -1: search again
  float reach = -1.0f;                           // a move shorter than this keeps `index` the nearest [m]
};

// Squared distance summed as the tree sums it (nanoflann's L2_Simple_Adaptor: axis by axis, in float), so a
// distance computed outside the tree (the odometry's ring walk, a memo's check) compares with the tree's bit
// for bit.
inline float treeSquaredDistance(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  float sum = 0.0f;
  for (int i = 0; i < 3; ++i) {
    const float d = a[i] - b[i];
    sum += d * d;
  }
  return sum;
}

class KdTree3 {
 public:
  KdTree3() = default;
  explicit KdTree3(std::vector<Eigen::Vector3d> points);

  // Index (into the points given at construction) of the nearest point with squared distance below
  // max_sq_distance, skipping index `exclude`; -1 if there is none.
  int nearest(const Eigen::Vector3d& query, double max_sq_distance, int exclude = -1) const;
  // The same answer (for a memo used with this tree only), from the memo while the query stays within its
  // reach, else searched (the two nearest, one pass) and remembered.
  int nearest(const Eigen::Vector3d& query, double max_sq_distance, NearestMemo& memo) const;

  // Indices of up to k nearest points with squared distance below max_sq_distance, nearest first, written
  // into `out` (its capacity is reused: no allocation per query in a loop).
  void nearestK(const Eigen::Vector3d& query, int k, double max_sq_distance, std::vector<int>& out) const;
  std::vector<int> nearestK(const Eigen::Vector3d& query, int k, double max_sq_distance) const {
    std::vector<int> out;
    nearestK(query, k, max_sq_distance, out);
    return out;
  }

  const Eigen::Vector3d& point(int index) const { return points()[static_cast<std::size_t>(index)]; }
  std::size_t size() const { return index_ ? points().size() : 0; }
  bool empty() const { return size() == 0; }

 private:
  struct Index;
  const std::vector<Eigen::Vector3d>& points() const;
  std::shared_ptr<const Index> index_;
};

}  // namespace adit
