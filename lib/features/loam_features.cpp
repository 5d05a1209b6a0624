#include "features/loam_features.hpp"

#include "features/preprocess.hpp"

#include <algorithm>
#include <numeric>

namespace adit::features {
namespace {

enum Label : std::uint8_t { kNone = 0, kEdge = 1, kFlat = 2 };

struct RingSelection {
  const RingCloud& c;
  const PointScores& s;
  const LoamConfig& cfg;
  int b, e;                        // ring span
  std::vector<std::uint8_t>& taken;  // picked or suppressed
  std::vector<std::uint8_t>& label;

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

  void sector(int sp, int ep, LoamFeatures& out) const {
    std::vector<int> order;
    for (int i = sp; i < ep; ++i)
      if (s.usable[i]) order.push_back(i);
    // Ascending smoothness, ties by index: deterministic.
    std::sort(order.begin(), order.end(), [&](int a, int k) {
      return s.smoothness[a] < s.smoothness[k] || (s.smoothness[a] == s.smoothness[k] && a < k);
    });
    int edges = 0;
    for (auto it = order.rbegin(); it != order.rend() && edges < cfg.max_less_sharp; ++it) {
      const int i = *it;
      if (s.smoothness[i] <= cfg.edge_threshold) break;
      if (taken[i]) continue;
      ++edges;
      if (edges <= cfg.max_sharp) out.sharp.push_back(c.points[i]);
      out.less_sharp.push_back(c.points[i]);
      label[i] = kEdge;
      suppress(i);
    }
    int flats = 0;
    for (int i : order) {
      if (flats >= cfg.max_flat || s.smoothness[i] >= cfg.surf_threshold) break;
      if (taken[i]) continue;
      ++flats;
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
  std::vector<LidarPoint> less_flat;
  const int sectors = std::max(1, cfg.sectors);
  for (int r = 0; r < c.numRings(); ++r) {
    const int b = c.ring_begin[r], e = c.ring_begin[r + 1];
    const int sp0 = b + cfg.half_window, ep0 = e - cfg.half_window;  // span with complete windows
    if (ep0 <= sp0) continue;
    RingSelection sel{c, s, cfg, b, e, taken, label};
    for (int k = 0; k < sectors; ++k)
      sel.sector(sp0 + (ep0 - sp0) * k / sectors, sp0 + (ep0 - sp0) * (k + 1) / sectors, out);
    for (int i = sp0; i < ep0; ++i)
      if (s.usable[i] && label[i] != kEdge && s.smoothness[i] <= cfg.edge_threshold) less_flat.push_back(c.points[i]);
  }
  out.less_flat = voxelDownsample(less_flat, cfg.less_flat_voxel);
  return out;
}

}  // namespace adit::features
