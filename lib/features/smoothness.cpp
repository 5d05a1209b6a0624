#include "features/smoothness.hpp"

#include <algorithm>
#include <cmath>

namespace adit::features {
namespace {

float azimuthGap(float a, float b) {
  float d = std::fabs(a - b);
  return d > static_cast<float>(M_PI) ? static_cast<float>(2.0 * M_PI) - d : d;
}

// Smoothness of points [b, e) of one ring; windows crossing a gap of missing returns are not evaluated.
void scoreRing(const RingCloud& c, int b, int e, const LoamConfig& cfg, PointScores& s) {
  const int w = cfg.half_window;
  const float max_gap = cfg.max_neighbor_gap_deg * static_cast<float>(M_PI / 180.0);
  // gaps_upto[k] = number of gaps between consecutive points among b..b+k
  std::vector<int> gaps_upto(e - b, 0);
  for (int i = b + 1; i < e; ++i)
    gaps_upto[i - b] = gaps_upto[i - 1 - b] + (azimuthGap(s.azimuth[i], s.azimuth[i - 1]) > max_gap ? 1 : 0);
  for (int i = b + w; i + w < e; ++i) {
    if (gaps_upto[i + w - b] != gaps_upto[i - w - b]) continue;
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    float spread = 0.0f;
    for (int j = i - w; j <= i + w; ++j) {
      const Eigen::Vector3f d = c.points[j].p - c.points[i].p;
      sum += d;
      spread += d.norm();
    }
    s.smoothness[i] = spread > 1e-6f ? sum.norm() / spread : 0.0f;
  }
}

// Marks the far side of depth jumps and beam-parallel points as unusable.
void markUnreliable(int b, int e, const LoamConfig& cfg, PointScores& s) {
  const int w = cfg.half_window;
  for (int i = b; i + 1 < e; ++i) {
    const float d0 = s.range[i], d1 = s.range[i + 1];
    if (d0 - d1 > cfg.occlusion_ratio * d1) {  // i lies behind the edge at i + 1
      for (int k = std::max(b, i - w); k <= i; ++k) s.usable[k] = 0;
    } else if (d1 - d0 > cfg.occlusion_ratio * d0) {  // i + 1 lies behind the edge at i
      for (int k = i + 1; k <= std::min(e - 1, i + 1 + w); ++k) s.usable[k] = 0;
    }
  }
  for (int i = b + 1; i + 1 < e; ++i) {
    const float d = s.range[i], tol = cfg.parallel_ratio * d;
    if (std::fabs(s.range[i - 1] - d) > tol && std::fabs(s.range[i + 1] - d) > tol) s.usable[i] = 0;
  }
}

}  // namespace

PointScores scorePoints(const RingCloud& c, const LoamConfig& cfg) {
  const std::size_t n = c.points.size();
  PointScores s;
  s.range.resize(n);
  s.azimuth.resize(n);
  s.smoothness.assign(n, -1.0f);
  s.usable.assign(n, 1);
  for (std::size_t i = 0; i < n; ++i) {
    s.range[i] = c.points[i].p.norm();
    s.azimuth[i] = std::atan2(c.points[i].p.y(), c.points[i].p.x());
  }
  for (int r = 0; r < c.numRings(); ++r) {
    const int b = c.ring_begin[r], e = c.ring_begin[r + 1];
    scoreRing(c, b, e, cfg, s);
    markUnreliable(b, e, cfg, s);
    for (int i = b; i < e; ++i)
      if (s.smoothness[i] < 0.0f) s.usable[i] = 0;
  }
  return s;
}

}  // namespace adit::features
