// A small static 3-D KD-tree for nearest-neighbour queries on one sweep's feature points.
//
// Built once per sweep (O(n log n), median splits with std::nth_element, no randomness) and queried a few
// thousand times. Only exact single-nearest queries are needed by scan-to-scan matching, so this is all it does.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace adit {

class KdTree3 {
 public:
  KdTree3() = default;
  explicit KdTree3(std::vector<Eigen::Vector3d> points);

  // Index (into the points given at construction) of the nearest point with squared distance below
  // max_sq_distance, skipping index `exclude`; -1 if there is none.
  int nearest(const Eigen::Vector3d& query, double max_sq_distance, int exclude = -1) const;

  // Indices of up to k nearest points with squared distance below max_sq_distance, nearest first.
  std::vector<int> nearestK(const Eigen::Vector3d& query, int k, double max_sq_distance) const;

  const Eigen::Vector3d& point(int index) const { return points_[static_cast<std::size_t>(index)]; }
  std::size_t size() const { return points_.size(); }
  bool empty() const { return points_.empty(); }

 private:
  void build(int lo, int hi);
  void search(int lo, int hi, const Eigen::Vector3d& q, int exclude, double& best_sq, int& best) const;

  struct Candidate {
    double sq;
    int index;
  };
  void searchK(int lo, int hi, const Eigen::Vector3d& q, int k, double max_sq, std::vector<Candidate>& best) const;

  std::vector<Eigen::Vector3d> points_;
  std::vector<int> order_;  // tree layout: the node of range [lo, hi) is order_[(lo + hi) / 2]
  std::vector<int> axis_;   // split axis of the node stored at each layout position
};

}  // namespace adit
