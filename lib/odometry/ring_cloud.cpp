#include "odometry/ring_cloud.hpp"

namespace adit {

RingIndexedCloud::RingIndexedCloud(const std::vector<LidarPoint>& points) {
  std::vector<Eigen::Vector3d> xyz;
  std::map<int, std::vector<Eigen::Vector3d>> ring_xyz;
  std::map<int, std::vector<int>> ring_index;
  xyz.reserve(points.size());
  rings_.reserve(points.size());
  for (const LidarPoint& p : points) {
    if (!p.p.allFinite()) continue;
    const int index = static_cast<int>(xyz.size());
    xyz.push_back(p.p.cast<double>());
    rings_.push_back(p.ring);
    index_in_ring_.push_back(static_cast<int>(ring_index[p.ring].size()));
    ring_xyz[p.ring].push_back(xyz.back());
    ring_index[p.ring].push_back(index);
  }
  all_ = KdTree3(std::move(xyz));
  for (auto& [ring, pts] : ring_xyz) by_ring_[ring] = Ring{KdTree3(std::move(pts)), std::move(ring_index[ring])};
}

int RingIndexedCloud::nearest(const Eigen::Vector3d& q, double max_sq_distance) const {
  return all_.nearest(q, max_sq_distance);
}

int RingIndexedCloud::nearestInRing(int ring, const Eigen::Vector3d& q, double max_sq_distance, int exclude) const {
  const auto it = by_ring_.find(ring);
  if (it == by_ring_.end()) return -1;
  const Ring& r = it->second;
  const bool exclude_here = exclude >= 0 && static_cast<std::size_t>(exclude) < rings_.size() && this->ring(exclude) == ring;
  const int local_exclude = exclude_here ? index_in_ring_[static_cast<std::size_t>(exclude)] : -1;
  const int local = r.tree.nearest(q, max_sq_distance, local_exclude);
  return local < 0 ? -1 : r.to_global[static_cast<std::size_t>(local)];
}

void RingIndexedCloud::nearestKInRing(int ring, const Eigen::Vector3d& q, int k, double max_sq_distance,
                                      std::vector<int>& out) const {
  out.clear();
  const auto it = by_ring_.find(ring);
  if (it == by_ring_.end()) return;
  it->second.tree.nearestK(q, k, max_sq_distance, out);
  for (int& i : out) i = it->second.to_global[static_cast<std::size_t>(i)];
}

int RingIndexedCloud::nearestInNeighbourRings(int ring, int window, const Eigen::Vector3d& q,
                                              double max_sq_distance) const {
  int best = -1;
  double best_sq = max_sq_distance;
  for (auto it = by_ring_.lower_bound(ring - window); it != by_ring_.end() && it->first <= ring + window; ++it) {
    if (it->first == ring) continue;
    const int local = it->second.tree.nearest(q, best_sq);
    if (local < 0) continue;
    best = it->second.to_global[static_cast<std::size_t>(local)];
    best_sq = (point(best) - q).squaredNorm();
  }
  return best;
}

}  // namespace adit
