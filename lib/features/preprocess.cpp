#include "features/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace adit::features {
namespace {

constexpr float kTwoPi = static_cast<float>(2.0 * M_PI);

bool insideBox(const Eigen::Vector3f& p, const PreprocessConfig& cfg) {
  const bool enabled = (cfg.body_box_min.array() < cfg.body_box_max.array()).all();
  return enabled && (p.array() >= cfg.body_box_min.array()).all() && (p.array() <= cfg.body_box_max.array()).all();
}

// Beams of the sensor; a corrupt ring field cannot make us allocate 65536 rings (points beyond are dropped).
int ringCount(const LidarScan& scan, const std::vector<LidarPoint>& pts, const PreprocessConfig& cfg) {
  if (scan.num_beams > 0) return std::min(scan.num_beams, kMaxRings);
  if (!scan.has_ring) return std::clamp(cfg.num_rings, 1, kMaxRings);
  int max_ring = 0;
  for (const LidarPoint& p : pts) max_ring = std::max<int>(max_ring, p.ring);
  return std::min(max_ring + 1, kMaxRings);
}

// Pointwise filters; counts what they drop.
std::vector<LidarPoint> keepValidPoints(const LidarScan& scan, const PreprocessConfig& cfg, PreprocessReport& rep) {
  std::vector<LidarPoint> out;
  out.reserve(scan.points.size());
  const float min2 = cfg.min_range * cfg.min_range, max2 = cfg.max_range * cfg.max_range;
  for (const LidarPoint& p : scan.points) {
    if (!p.p.allFinite() || (scan.has_time && !std::isfinite(p.dt))) {
      ++rep.removed_invalid;
      continue;
    }
    const float r2 = p.p.squaredNorm();
    if (r2 < min2 || r2 > max2 || insideBox(p.p, cfg)) {
      ++rep.removed_range;
      continue;
    }
    out.push_back(p);
  }
  return out;
}

// Rings and times filled in when the scan lacks them; points on rings beyond the sensor's count dropped.
void completeRingsAndTimes(const LidarScan& scan, const PreprocessConfig& cfg, int num_rings,
                           std::vector<LidarPoint>& pts, PreprocessReport& rep) {
  rep.ring_derived = !scan.has_ring;
  rep.time_derived = !scan.has_time;
  const float sweep = std::max(scan.sweep_duration, 1e-3f);
  const float seam = pts.empty() ? 0.0f : std::atan2(pts.front().p.y(), pts.front().p.x());
  std::size_t kept = 0;
  for (LidarPoint& p : pts) {
    if (!scan.has_ring) p.ring = static_cast<std::uint16_t>(
        ringFromElevation(p.p, num_rings, cfg.min_elevation_deg, cfg.max_elevation_deg));
    if (p.ring >= num_rings) {
      ++rep.removed_range;
      continue;
    }
    p.dt = scan.has_time ? std::clamp(p.dt, -sweep, 0.0f) : timeFromAzimuth(p.p, seam, sweep, cfg.clockwise);
    pts[kept++] = p;
  }
  pts.resize(kept);
}

// Counting sort by ring (stable), then firing order inside each ring.
RingCloud groupByRing(const std::vector<LidarPoint>& pts, int num_rings) {
  RingCloud cloud;
  cloud.ring_begin.assign(num_rings + 1, 0);
  for (const LidarPoint& p : pts) ++cloud.ring_begin[p.ring + 1];
  for (int r = 0; r < num_rings; ++r) cloud.ring_begin[r + 1] += cloud.ring_begin[r];
  std::vector<int> next(cloud.ring_begin.begin(), cloud.ring_begin.end() - 1);
  cloud.points.resize(pts.size());
  for (const LidarPoint& p : pts) cloud.points[next[p.ring]++] = p;
  const auto by_time = [](const LidarPoint& a, const LidarPoint& b) { return a.dt < b.dt; };
  for (int r = 0; r < num_rings; ++r) {
    auto first = cloud.points.begin() + cloud.ring_begin[r], last = cloud.points.begin() + cloud.ring_begin[r + 1];
    if (std::is_sorted(first, last, by_time)) continue;
    // A row that starts mid-sweep (KITTI) is two sorted runs: rotating them equals the stable sort.
    const auto mid = std::min_element(first, last, by_time);
    if (std::is_sorted(mid, last, by_time) && std::is_sorted(first, mid, by_time) && by_time(*(last - 1), *first))
      std::rotate(first, mid, last);
    else
      std::stable_sort(first, last, by_time);
  }
  return cloud;
}

int neighboursWithin(const RingCloud& c, int i, int first, int last, int center, int window, float radius2) {
  int count = 0;
  for (int j = std::max(first, center - window); j <= std::min(last - 1, center + window); ++j)
    if (j != i && (c.points[j].p - c.points[i].p).squaredNorm() < radius2) ++count;
  return count;
}

// Keeps a point if enough neighbours on its ring and the adjacent rings (at the same firing time) are near.
std::vector<char> radiusInliers(const RingCloud& c, const PreprocessConfig& cfg) {
  std::vector<char> keep(c.points.size(), 1);
  if (cfg.outlier_min_neighbors <= 0) return keep;
  for (int r = 0; r < c.numRings(); ++r) {
    int cursor[2] = {r > 0 ? c.ring_begin[r - 1] : 0, r + 1 < c.numRings() ? c.ring_begin[r + 1] : 0};
    for (int i = c.ring_begin[r]; i < c.ring_begin[r + 1]; ++i) {
      const float range = c.points[i].p.norm();
      if (range >= cfg.outlier_max_range) continue;
      const float radius = cfg.outlier_radius + cfg.outlier_radius_per_m * range;
      int count = neighboursWithin(c, i, c.ring_begin[r], c.ring_begin[r + 1], i, cfg.outlier_window, radius * radius);
      for (int side = 0; side < 2 && count < cfg.outlier_min_neighbors; ++side) {
        const int adj = side == 0 ? r - 1 : r + 1;
        if (adj < 0 || adj >= c.numRings() || c.ringSize(adj) == 0) continue;
        int& k = cursor[side];  // last point of the adjacent ring fired no later than point i
        while (k + 1 < c.ring_begin[adj + 1] && c.points[k + 1].dt <= c.points[i].dt) ++k;
        count += neighboursWithin(c, i, c.ring_begin[adj], c.ring_begin[adj + 1], k, cfg.outlier_window,
                                  radius * radius);
      }
      keep[i] = count >= cfg.outlier_min_neighbors;
    }
  }
  return keep;
}

RingCloud removeOutliers(const RingCloud& c, const PreprocessConfig& cfg, PreprocessReport& rep) {
  const std::vector<char> keep = radiusInliers(c, cfg);
  RingCloud out;
  out.ring_begin.assign(c.ring_begin.size(), 0);
  out.points.reserve(c.points.size());
  for (int r = 0; r < c.numRings(); ++r) {
    for (int i = c.ring_begin[r]; i < c.ring_begin[r + 1]; ++i) {
      if (keep[i]) out.points.push_back(c.points[i]);
      else ++rep.removed_outlier;
    }
    out.ring_begin[r + 1] = static_cast<int>(out.points.size());
  }
  return out;
}

}  // namespace

int ringFromElevation(const Eigen::Vector3f& p, int num_rings, float min_elevation_deg, float max_elevation_deg) {
  if (num_rings <= 1) return 0;
  const float elevation = std::atan2(p.z(), std::hypot(p.x(), p.y())) * static_cast<float>(180.0 / M_PI);
  const float step = (max_elevation_deg - min_elevation_deg) / static_cast<float>(num_rings - 1);
  if (!(step > 0.0f)) return 0;
  const int ring = static_cast<int>(std::lround((elevation - min_elevation_deg) / step));
  return std::clamp(ring, 0, num_rings - 1);
}

float timeFromAzimuth(const Eigen::Vector3f& p, float seam_azimuth, float sweep_duration, bool clockwise) {
  const float azimuth = std::atan2(p.y(), p.x());
  float swept = clockwise ? seam_azimuth - azimuth : azimuth - seam_azimuth;
  swept = std::fmod(swept, kTwoPi);
  if (swept < 0.0f) swept += kTwoPi;
  return sweep_duration * (swept / kTwoPi - 1.0f);
}

RingCloud preprocessScan(const LidarScan& scan, const PreprocessConfig& cfg, PreprocessReport* report) {
  PreprocessReport rep;
  rep.points_in = static_cast<int>(scan.points.size());
  std::vector<LidarPoint> pts = keepValidPoints(scan, cfg, rep);
  const int num_rings = ringCount(scan, pts, cfg);
  completeRingsAndTimes(scan, cfg, num_rings, pts, rep);
  RingCloud cloud = removeOutliers(groupByRing(pts, num_rings), cfg, rep);
  if (report) *report = rep;
  return cloud;
}

std::vector<LidarPoint> voxelDownsample(const std::vector<LidarPoint>& points, float leaf) {
  if (!(leaf > 0.0f) || points.empty()) return points;
  // Open-addressing table voxel key -> output slot, used for lookup only: the output is in order of first
  // occurrence, so the result does not depend on hashing. Node-free: no allocation per voxel.
  std::size_t capacity = 16;
  while (capacity < 2 * points.size()) capacity <<= 1;
  constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  std::vector<std::uint64_t> keys(capacity, kEmpty);
  std::vector<int> slots(capacity, -1);
  std::vector<LidarPoint> out;
  std::vector<Eigen::Vector3f> sums;
  std::vector<int> counts;
  const float inv = 1.0f / leaf;
  for (const LidarPoint& p : points) {
    // Clamped so that the cast cannot overflow (a tiny leaf or a far point); the key keeps 21 bits anyway.
    const Eigen::Array3f q = (p.p.array() * inv).floor().max(-1e15f).min(1e15f);
    const std::uint64_t key = ((static_cast<std::uint64_t>(static_cast<std::int64_t>(q.x())) & 0x1FFFFF) << 42) |
                              ((static_cast<std::uint64_t>(static_cast<std::int64_t>(q.y())) & 0x1FFFFF) << 21) |
                              (static_cast<std::uint64_t>(static_cast<std::int64_t>(q.z())) & 0x1FFFFF);
    std::size_t h = (key * 0x9E3779B97F4A7C15ull) >> 20 & (capacity - 1);
    while (keys[h] != kEmpty && keys[h] != key) h = (h + 1) & (capacity - 1);
    if (keys[h] == kEmpty) {
      keys[h] = key;
      slots[h] = static_cast<int>(out.size());
      out.push_back(p);
      sums.push_back(p.p);
      counts.push_back(1);
    } else {
      sums[slots[h]] += p.p;
      ++counts[slots[h]];
    }
  }
  for (std::size_t k = 0; k < out.size(); ++k) out[k].p = sums[k] / static_cast<float>(counts[k]);
  return out;
}

}  // namespace adit::features
