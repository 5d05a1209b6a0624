#include "mapping/downsample.hpp"

#include "mapping/voxel_key.hpp"

#include <algorithm>
#include <numeric>

namespace adit {

// The cells are found through an open-addressing table sized for every point (linear probing, at most half
// full, never grown), so a new cell costs no allocation: std::unordered_map allocated a node per cell, and
// with its buckets this thinning was 4 % of a replay's CPU (the mapper's two per sweep). Each cell sums its
// points in input order, and the cells are listed sorted by key: the result does not depend on the table.
std::vector<Eigen::Vector3d> voxelDownsample(const std::vector<Eigen::Vector3d>& points, double voxel_size) {
  std::vector<Eigen::Vector3d> out;
  if (voxel_size <= 0) {
    std::copy_if(points.begin(), points.end(), std::back_inserter(out),
                 [](const Eigen::Vector3d& p) { return p.allFinite(); });
    return out;
  }
  struct Cell {
    VoxelKey key;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
  };
  std::vector<Cell> cells;
  cells.reserve(points.size());
  std::size_t slots = 16;
  while (slots < 2 * points.size()) slots <<= 1;
  std::vector<std::int32_t> table(slots, -1);
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    Cell& c = cells[voxelFindOrAdd(table, cells, voxelOf(p, voxel_size))];
    c.sum += p;
    ++c.count;
  }
  std::vector<std::int32_t> order(cells.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) {
    return cells[static_cast<std::size_t>(a)].key < cells[static_cast<std::size_t>(b)].key;
  });
  out.reserve(cells.size());
  for (const std::int32_t i : order) {
    const Cell& c = cells[static_cast<std::size_t>(i)];
    out.push_back(c.sum / c.count);
  }
  return out;
}

}  // namespace adit
