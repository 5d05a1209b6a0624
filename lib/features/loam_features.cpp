#include "features/loam_features.hpp"

#include "features/voxel_centroids.hpp"

#include <algorithm>
#include <cstring>
#include <functional>

namespace adit::features {
namespace {

enum Label : std::uint8_t { kNone = 0, kEdge = 1, kFlat = 2 };

// Sorted access to unique keys without sorting them all: only the first `prefix` are ordered up front (the
// picks rarely need more: each pick suppresses at most 2 half_window neighbours); each time the ordered part
// runs out, the next block, twice as long, is selected and sorted. Same order as a full sort.
template <class Compare>
class SortedPrefix {
 public:
  SortedPrefix(std::vector<std::uint64_t>& keys, std::size_t prefix) : keys_(keys), block_(std::max<std::size_t>(prefix, 1)) {
    orderUpTo(block_);
  }
  std::uint64_t at(std::size_t k) {
    while (k >= sorted_) orderUpTo(sorted_ + (block_ *= 2));
    return keys_[k];
  }

 private:
  void orderUpTo(std::size_t end) {
    end = std::min(end, keys_.size());
    if (end < keys_.size()) std::nth_element(keys_.begin() + sorted_, keys_.begin() + end, keys_.end(), Compare{});
    std::sort(keys_.begin() + sorted_, keys_.begin() + end, Compare{});
    sorted_ = end;
  }

  std::vector<std::uint64_t>& keys_;
  std::size_t block_;
  std::size_t sorted_ = 0;
};

struct RingSelection {
  const RingCloud& c;
  const PointScores& s;
  const LoamConfig& cfg;
  int b, e;                        // ring span
  std::vector<std::uint8_t>& taken;  // picked or suppressed
  std::vector<std::uint8_t>& label;
  std::vector<std::uint64_t>& edges;  // sort keys of one sector's candidates (reused: no allocation per sector)
  std::vector<std::uint64_t>& flats;

  // Suppress neighbours of i on the same surface (stop at a gap larger than suppression_gap).
  void suppress(int i) const {
    taken[i] = 1;
    const float gap2 = cfg.suppression_gap * cfg.suppression_gap;
    for (int l = 1; l <= cfg.half_window && i + l < e; ++l) {
      if ((c.points[i + l].p - c.points[i + l - 1].p).squaredNorm() > gap2) break;
      taken[i + l] = 1;
    }
    for (int l = 1; l <= cfg.half_window && i - l >= b; ++l) {
      if ((c.points[i - l].p - c.points[i - l + 1].p).squaredNorm() > gap2) break;
      taken[i - l] = 1;
    }
  }

  bool isEdge(int i) const {
    return s.usable[i] && s.smoothness[i] > cfg.edge_threshold &&
           s.offset[i] > std::max(cfg.edge_min_offset, cfg.edge_noise_factor * s.noise);
  }
  bool isFlat(int i) const {
    return s.usable[i] && !isEdge(i) && (s.smoothness[i] < cfg.surf_threshold || s.offset[i] < cfg.surf_max_offset);
  }

  void sector(int sp, int ep, LoamFeatures& out) const {
    // Sort keys: smoothness bits (non-negative floats order like their bit patterns) above the index, so
    // a plain integer sort orders by smoothness with ties by index: fast and deterministic.
    edges.clear();
    flats.clear();
    for (int i = sp; i < ep; ++i) {
      std::uint32_t bits;
      std::memcpy(&bits, &s.smoothness[i], sizeof bits);
      const std::uint64_t key = (static_cast<std::uint64_t>(bits) << 32) | static_cast<std::uint32_t>(i);
      if (isEdge(i)) edges.push_back(key);
      else if (isFlat(i)) flats.push_back(key);
    }
    SortedPrefix<std::greater<>> edge_order(edges, static_cast<std::size_t>(cfg.max_less_sharp) * 2);
    SortedPrefix<std::less<>> flat_order(flats, static_cast<std::size_t>(cfg.max_flat) * 4);
    int picked = 0;
    for (std::size_t k = 0; k < edges.size() && picked < cfg.max_less_sharp; ++k) {
      const int i = static_cast<int>(edge_order.at(k) & 0xFFFFFFFFu);
      if (taken[i]) continue;
      ++picked;
      if (picked <= cfg.max_sharp) out.sharp.push_back(c.points[i]);
      out.less_sharp.push_back(c.points[i]);
      label[i] = kEdge;
      suppress(i);
    }
    picked = 0;
    for (std::size_t k = 0; k < flats.size() && picked < cfg.max_flat; ++k) {
      const int i = static_cast<int>(flat_order.at(k) & 0xFFFFFFFFu);
      if (taken[i]) continue;
      ++picked;
      out.flat.push_back(c.points[i]);
      label[i] = kFlat;
      suppress(i);
    }
  }
};

}  // namespace

LoamFeatures selectLoamFeatures(const RingCloud& c, const PointScores& s, const LoamConfig& cfg) {
  LoamFeatures out;
  std::vector<std::uint8_t> taken(c.points.size(), 0), label(c.points.size(), kNone);
  std::vector<std::uint64_t> edges, flats;
  // Less flat points go straight into the voxel grid (no copy of them all first); a leaf <= 0 keeps them all.
  const bool downsample = cfg.less_flat_voxel > 0.0f;
  VoxelCentroids grid(downsample ? cfg.less_flat_voxel : 1.0f, c.points.size(), cfg.less_flat_measured);
  const int sectors = std::max(1, cfg.sectors);
  for (int r = 0; r < c.numRings(); ++r) {
    const int b = c.ring_begin[r], e = c.ring_begin[r + 1];
    const int sp0 = b + cfg.half_window, ep0 = e - cfg.half_window;  // span with complete windows
    if (ep0 <= sp0) continue;
    RingSelection sel{c, s, cfg, b, e, taken, label, edges, flats};
    for (int k = 0; k < sectors; ++k)
      sel.sector(sp0 + (ep0 - sp0) * k / sectors, sp0 + (ep0 - sp0) * (k + 1) / sectors, out);
    for (int i = sp0; i < ep0; ++i)
      if (s.usable[i] && label[i] != kEdge && !sel.isEdge(i)) {
        // Measured less-flat points include every flat point (as LOAM defines the set), so a flat point
        // of the next sweep can find its own surface point rather than a neighbour's plane.
        if (!downsample || (cfg.less_flat_measured && label[i] == kFlat)) out.less_flat.push_back(c.points[i]);
        else grid.add(c.points[i]);
      }
  }
  if (downsample) {
    std::vector<LidarPoint> sampled = grid.take();
    out.less_flat.insert(out.less_flat.end(), sampled.begin(), sampled.end());
  }
  return out;
}

}  // namespace adit::features
