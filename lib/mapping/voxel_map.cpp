#include "mapping/voxel_map.hpp"

#include <algorithm>
#include <map>

namespace adit {

VoxelMap::VoxelMap(double voxel_size, double min_spacing, int max_points_per_voxel)
    : voxel_size_(voxel_size > 0 ? voxel_size : 1.0),
      min_spacing_sq_(min_spacing * min_spacing),
      max_points_per_voxel_(std::max(1, max_points_per_voxel)) {}

void VoxelMap::insert(const std::vector<Eigen::Vector3d>& points) {
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    auto& cell = voxels_[voxelOf(p, voxel_size_)];
    if (static_cast<int>(cell.size()) >= max_points_per_voxel_) continue;
    const bool crowded = std::any_of(cell.begin(), cell.end(),
                                     [&](const Eigen::Vector3d& o) { return (o - p).squaredNorm() < min_spacing_sq_; });
    if (crowded) continue;
    cell.push_back(p);
    ++num_points_;
  }
}

void VoxelMap::removeFarFrom(const Eigen::Vector3d& centre, double radius) {
  const double r_sq = radius * radius;
  for (auto it = voxels_.begin(); it != voxels_.end();) {
    const Eigen::Vector3d c((it->first.x + 0.5) * voxel_size_, (it->first.y + 0.5) * voxel_size_,
                            (it->first.z + 0.5) * voxel_size_);
    if ((c - centre).squaredNorm() > r_sq) {
      num_points_ -= it->second.size();
      it = voxels_.erase(it);
    } else {
      ++it;
    }
  }
}

void VoxelMap::transform(const Eigen::Isometry3d& T) {
  std::vector<Eigen::Vector3d> moved = points();
  for (Eigen::Vector3d& p : moved) p = T * p;
  voxels_.clear();
  num_points_ = 0;
  insert(moved);
}

std::vector<Eigen::Vector3d> VoxelMap::nearest(const Eigen::Vector3d& q, int k, double max_distance) const {
  std::vector<Eigen::Vector3d> out;
  nearest(q, k, max_distance, out);
  return out;
}

void VoxelMap::nearest(const Eigen::Vector3d& q, int k, double max_distance, std::vector<Eigen::Vector3d>& out) const {
  out.clear();
  if (k <= 0 || !q.allFinite()) return;
  // The k best so far, ascending (a fixed buffer: no allocation while searching).
  constexpr int kStack = 32;
  std::pair<double, const Eigen::Vector3d*> stack[kStack];
  std::vector<std::pair<double, const Eigen::Vector3d*>> heap;
  auto* best = stack;
  if (k > kStack) {
    heap.resize(static_cast<std::size_t>(k));
    best = heap.data();
  }
  int count = 0;
  const double max_sq = max_distance * max_distance;
  const auto bound = [&] { return count < k ? max_sq : best[k - 1].first; };
  const VoxelKey c = voxelOf(q, voxel_size_);
  // Squared distance from q to the faces of its voxel, below and above, per axis: a neighbour voxel is
  // skipped when its box is farther than the current k-th best (most of the 26 once the k best are found).
  const Eigen::Vector3d lo = q - Eigen::Vector3d(c.x, c.y, c.z) * voxel_size_;
  const Eigen::Vector3d hi = Eigen::Vector3d::Constant(voxel_size_) - lo;
  const auto face_sq = [&](int axis, int d) { return d == 0 ? 0.0 : (d < 0 ? lo[axis] * lo[axis] : hi[axis] * hi[axis]); };
  // The query's own voxel first (it holds the nearest points most often), then per axis the neighbour across
  // the nearer face before the one across the farther face: the k-th best shrinks early and prunes more.
  int order[3][3];
  for (int axis = 0; axis < 3; ++axis) {
    const int nearer = lo[axis] <= hi[axis] ? -1 : 1;
    order[axis][0] = 0;
    order[axis][1] = nearer;
    order[axis][2] = -nearer;
  }
  for (int dx : order[0])
    for (int dy : order[1])
      for (int dz : order[2]) {
        if (face_sq(0, dx) + face_sq(1, dy) + face_sq(2, dz) >= bound()) continue;
        const auto it = voxels_.find({c.x + dx, c.y + dy, c.z + dz});
        if (it == voxels_.end()) continue;
        for (const Eigen::Vector3d& p : it->second) {
          const double sq = (p - q).squaredNorm();
          if (!(sq < bound())) continue;
          // Insertion keeps the order stable for equal distances (first found wins): deterministic.
          int i = std::min(count, k - 1);
          for (; i > 0 && best[i - 1].first > sq; --i) best[i] = best[i - 1];
          best[i] = {sq, &p};
          count = std::min(count + 1, k);
        }
      }
  for (int i = 0; i < count; ++i) out.push_back(*best[i].second);
}

std::vector<Eigen::Vector3d> VoxelMap::points() const {
  std::map<VoxelKey, const std::vector<Eigen::Vector3d>*> sorted;
  for (const auto& kv : voxels_) sorted.emplace(kv.first, &kv.second);
  std::vector<Eigen::Vector3d> out;
  out.reserve(num_points_);
  for (const auto& kv : sorted) out.insert(out.end(), kv.second->begin(), kv.second->end());
  return out;
}

}  // namespace adit
