#include "mapping/voxel_map.hpp"

#include <algorithm>

namespace adit {
namespace {

constexpr std::size_t kInitialSlots = 64;

}  // namespace

VoxelMap::VoxelMap(double voxel_size, double min_spacing, int max_points_per_voxel)
    : voxel_size_(voxel_size > 0 ? voxel_size : 1.0),
      min_spacing_sq_(min_spacing * min_spacing),
      max_points_per_voxel_(std::max(1, max_points_per_voxel)),
      table_(kInitialSlots, kEmpty) {}

std::size_t VoxelMap::slotOf(const VoxelKey& key) const { return voxelSlot(table_, voxels_, key); }

const VoxelMap::Voxel* VoxelMap::find(const VoxelKey& key) const {
  const std::int32_t index = table_[slotOf(key)];
  return index == kEmpty ? nullptr : &voxels_[static_cast<std::size_t>(index)];
}

VoxelMap::Voxel& VoxelMap::findOrAdd(const VoxelKey& key) { return voxels_[voxelFindOrAdd(table_, voxels_, key)]; }

// Linear probing's deletion without tombstones: later entries of the probe run move back into the gap when
// their home slot does not lie between the gap and themselves.
void VoxelMap::eraseSlot(std::size_t slot) {
  const std::size_t mask = table_.size() - 1;
  table_[slot] = kEmpty;
  for (std::size_t next = (slot + 1) & mask; table_[next] != kEmpty; next = (next + 1) & mask) {
    const std::size_t home = mixedVoxelHash(voxels_[static_cast<std::size_t>(table_[next])].key) & mask;
    const bool stays = slot <= next ? (slot < home && home <= next) : (slot < home || home <= next);
    if (stays) continue;
    table_[slot] = table_[next];
    table_[next] = kEmpty;
    slot = next;
  }
}

// Without thin_among_them a new sweep is thinned against the sweeps before it only: its points come thinned
// by their own grid, and where the map dropped one of two neighbouring centroids of a 16-beam sweep, the next
// sweep's point there matched the neighbour, up to a resolution away, on a plane through it that a curved
// wall leaves on one side (the mapper's first registration at rest moved 15 mm, issue 16).
void VoxelMap::insert(const std::vector<Eigen::Vector3d>& points, bool thin_among_them) {
  const auto crowded = [this](const std::vector<Eigen::Vector3d>& cell, const Eigen::Vector3d& p) {
    return std::any_of(cell.begin(), cell.end(), [&](const Eigen::Vector3d& o) { return (o - p).squaredNorm() < min_spacing_sq_; });
  };
  std::vector<char> keep(points.size(), 1);
  if (!thin_among_them) {  // judged against the map as it was, before any of these points went in
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Voxel* cell = points[i].allFinite() ? find(voxelOf(points[i], voxel_size_)) : nullptr;
      keep[i] = !cell || !crowded(cell->points, points[i]);
    }
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    if (!keep[i] || !p.allFinite()) continue;
    auto& cell = findOrAdd(voxelOf(p, voxel_size_)).points;
    if (static_cast<int>(cell.size()) >= max_points_per_voxel_ || (thin_among_them && crowded(cell, p))) continue;
    cell.push_back(p);
    ++num_points_;
  }
}

void VoxelMap::removeFarFrom(const Eigen::Vector3d& centre, double radius) {
  const double r_sq = radius * radius;
  for (std::size_t v = 0; v < voxels_.size();) {
    const VoxelKey& k = voxels_[v].key;
    const Eigen::Vector3d c((k.x + 0.5) * voxel_size_, (k.y + 0.5) * voxel_size_, (k.z + 0.5) * voxel_size_);
    if (!((c - centre).squaredNorm() > r_sq)) {
      ++v;
      continue;
    }
    // The last voxel takes this one's place in the array (and in its table slot); v is looked at again.
    num_points_ -= voxels_[v].points.size();
    eraseSlot(slotOf(k));
    const std::size_t last = voxels_.size() - 1;
    if (v != last) {
      voxels_[v] = std::move(voxels_[last]);
      table_[slotOf(voxels_[v].key)] = static_cast<std::int32_t>(v);
    }
    voxels_.pop_back();
  }
}

void VoxelMap::transform(const Eigen::Isometry3d& T) {
  std::vector<Eigen::Vector3d> moved = points();
  for (Eigen::Vector3d& p : moved) p = T * p;
  voxels_.clear();
  table_.assign(kInitialSlots, kEmpty);
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
        const Voxel* voxel = find({c.x + dx, c.y + dy, c.z + dz});
        if (!voxel) continue;
        for (const Eigen::Vector3d& p : voxel->points) {
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
  std::vector<const Voxel*> sorted;
  sorted.reserve(voxels_.size());
  for (const Voxel& v : voxels_) sorted.push_back(&v);
  std::sort(sorted.begin(), sorted.end(), [](const Voxel* a, const Voxel* b) { return a->key < b->key; });
  std::vector<Eigen::Vector3d> out;
  out.reserve(num_points_);
  for (const Voxel* v : sorted) out.insert(out.end(), v->points.begin(), v->points.end());
  return out;
}

}  // namespace adit
