#include "features/smoothness.hpp"

#include "core/chunk_pool.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace adit::features {
namespace {

// True if the horizontal directions of a and b differ by more than the angle whose sine is sin_max (or by
// more than 90 deg): a gap of missing returns between consecutive points of a ring.
bool azimuthGap(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float sin_max) {
  const float dot = a.x() * b.x() + a.y() * b.y(), cross = a.x() * b.y() - a.y() * b.x();
  const float norms2 = (a.x() * a.x() + a.y() * a.y()) * (b.x() * b.x() + b.y() * b.y());
  return dot <= 0.0f || cross * cross > sin_max * sin_max * norms2;
}

// Prefix sums of one ring, reused from ring to ring (sized for the longest).
struct RingPrefix {
  std::vector<int> gaps;           // gaps[k]: gaps between consecutive points among b..b+k
  std::vector<Eigen::Vector3d> P;  // P[k] = sum of the first k points
  std::vector<double> C;           // C[k] = path length from b to b+k
  std::vector<double> CC;          // CC[k] = sum of the first k path lengths
};

// Smoothness of points [b, e) of one ring in O(1) per point from prefix sums (doubles: a ring's sums reach
// 1e5 m). The spread sum_j |p_j - p_i| is taken along the scan line (path length from p_i to p_j): equal to
// the chord on straight runs and at corners, larger where noise makes the line zigzag, so noise alone reads
// as less edge-like. Windows crossing a gap of missing returns are not evaluated.
void scoreRing(const RingCloud& c, int b, int e, const LoamConfig& cfg, RingPrefix& prefix, PointScores& s) {
  const int w = cfg.half_window, n = e - b;
  if (w < 1 || w >= n) return;  // no complete window (a half_window < 1 would index before the ring)
  const float sin_max = std::sin(std::min(cfg.max_neighbor_gap_deg, 89.0f) * static_cast<float>(M_PI / 180.0));
  std::vector<int>& gaps = prefix.gaps;
  std::vector<Eigen::Vector3d>& P = prefix.P;
  std::vector<double>& C = prefix.C;
  std::vector<double>& CC = prefix.CC;
  gaps.resize(n);  // every element below is written before it is read: no zero fill
  P.resize(n + 1);
  C.resize(n);
  CC.resize(n + 1);
  gaps[0] = 0;
  C[0] = 0.0;
  CC[0] = 0.0;
  P[0].setZero();
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3f& p = c.points[b + k].p;
    P[k + 1] = P[k] + p.cast<double>();
    if (k > 0) {
      const Eigen::Vector3f& q = c.points[b + k - 1].p;
      gaps[k] = gaps[k - 1] + (azimuthGap(q, p, sin_max) ? 1 : 0);
      C[k] = C[k - 1] + (p - q).norm();
    }
    CC[k + 1] = CC[k] + C[k];
  }
  for (int l = w; l + w < n; ++l) {
    if (gaps[l + w] != gaps[l - w]) continue;
    const Eigen::Vector3d sum = (P[l + w + 1] - P[l - w]) - (2 * w + 1) * c.points[b + l].p.cast<double>();
    const double spread = (CC[l + w + 1] - CC[l + 1]) - (CC[l] - CC[l - w]);
    const double norm = sum.norm();
    s.smoothness[b + l] = spread > 1e-6 ? static_cast<float>(norm / spread) : 0.0f;
    s.offset[b + l] = static_cast<float>(norm / (2 * w));
  }
}

// Second-difference lengths of points [b, e) of one ring whose two steps are both shorter than max_step
// (see PointScores::noise).
void collectSecondDifferences(const RingCloud& c, int b, int e, float max_step, std::vector<float>& out) {
  const float max_sq = max_step * max_step;
  for (int j = b + 1; j + 1 < e; ++j) {
    const Eigen::Vector3f &p = c.points[j - 1].p, &q = c.points[j].p, &r = c.points[j + 1].p;
    if ((q - p).squaredNorm() > max_sq || (r - q).squaredNorm() > max_sq) continue;
    out.push_back((p - 2.0f * q + r).norm());
  }
}

// The k-th smallest of non-negative floats (what std::nth_element would put at k), by radix selection on
// their bit patterns, which order like the values: per 11-bit digit, from the top, count, find the digit
// holding rank k, keep only those values. No data-dependent branches (nth_element's partitioning of noise
// mispredicts half of them).
float kthSmallestNonNegative(const std::vector<float>& values, std::size_t k) {
  std::vector<std::uint32_t> bits, keep;  // the candidates (all values, until the first digit is known)
  const auto bitsOf = [](float v) {
    std::uint32_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
  };
  const std::size_t n = values.size();
  for (const int shift : {21, 10, 0}) {  // digits of bits 31..21, 20..10, 10..0
    const bool first = shift == 21;
    const std::size_t m = first ? n : bits.size();
    const auto at = [&](std::size_t i) { return first ? bitsOf(values[i]) : bits[i]; };
    std::size_t counts[2048] = {};
    for (std::size_t i = 0; i < m; ++i) ++counts[(at(i) >> shift) & 0x7FF];
    std::size_t digit = 0;
    while (k >= counts[digit]) k -= counts[digit++];
    keep.clear();
    for (std::size_t i = 0; i < m; ++i)
      if (((at(i) >> shift) & 0x7FF) == digit) keep.push_back(at(i));
    bits.swap(keep);
  }
  float v;
  std::memcpy(&v, &bits.front(), sizeof v);
  return v;
}

float medianNoise(const std::vector<float>& second) {
  if (second.size() < 100) return 0.0f;
  // median of |N(0, 6 sigma^2)| = 0.6745 sqrt(6) sigma
  return kthSmallestNonNegative(second, second.size() / 2) / 1.652f;
}

// Marks the far side of depth jumps and beam-parallel points as unusable.
void markUnreliable(int b, int e, const LoamConfig& cfg, PointScores& s) {
  const int w = std::clamp(cfg.half_window, 0, e - b);  // i + 1 + w must not overflow
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

PointScores scorePoints(const RingCloud& c, const LoamConfig& cfg, ChunkPool* pool) {
  const std::size_t n = c.points.size();
  PointScores s;
  s.range.resize(n);
  s.smoothness.assign(n, -1.0f);
  s.offset.assign(n, 0.0f);
  s.usable.assign(n, 1);
  // Each group of rings writes its own points' scores and its own second differences.
  const int groups = pool ? std::min(pool->threads(), std::max(1, c.numRings())) : 1;
  std::vector<std::vector<float>> second(static_cast<std::size_t>(groups));
  const auto score = [&](int group, std::size_t ring_begin, std::size_t ring_end) {
    std::vector<float>& out = second[static_cast<std::size_t>(group)];
    RingPrefix prefix;
    for (int r = static_cast<int>(ring_begin); r < static_cast<int>(ring_end); ++r) {
      const int b = c.ring_begin[r], e = c.ring_begin[r + 1];
      for (int i = b; i < e; ++i) s.range[i] = c.points[i].p.norm();
      scoreRing(c, b, e, cfg, prefix, s);
      collectSecondDifferences(c, b, e, cfg.noise_max_step, out);
      markUnreliable(b, e, cfg, s);
      for (int i = b; i < e; ++i)
        if (s.smoothness[i] < 0.0f) s.usable[i] = 0;
    }
  };
  if (pool && groups > 1) pool->run(static_cast<std::size_t>(c.numRings()), groups, score);
  else score(0, 0, static_cast<std::size_t>(c.numRings()));
  // The median does not depend on the order the groups' differences are joined in.
  for (std::size_t g = 1; g < second.size(); ++g) second[0].insert(second[0].end(), second[g].begin(), second[g].end());
  s.noise = medianNoise(second[0]);
  return s;
}

}  // namespace adit::features
