#include "features/preprocess.hpp"

#include "features/voxel_centroids.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace adit::features {
namespace {

constexpr float kTwoPi = static_cast<float>(2.0 * M_PI);

bool insideBox(const Eigen::Vector3f& p, const PreprocessConfig& cfg) {
  const bool enabled = (cfg.body_box_min.array() < cfg.body_box_max.array()).all();
  return enabled && (p.array() >= cfg.body_box_min.array()).all() && (p.array() <= cfg.body_box_max.array()).all();
}

constexpr std::uint16_t kDropped = 0xFFFF;  // no ring: the point was dropped (a kept ring is < kMaxRings)

// Pointwise filters; counts what they drop. ring_of[i] = the point's ring field if kept, else kDropped.
// Returns the index of the first kept point (the seam for times from azimuth), or -1.
long markValidPoints(const LidarScan& scan, const PreprocessConfig& cfg, std::vector<std::uint16_t>& ring_of,
                     int& max_ring, PreprocessReport& rep) {
  const float min2 = cfg.min_range * cfg.min_range, max2 = cfg.max_range * cfg.max_range;
  long first = -1;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const LidarPoint& p = scan.points[i];
    ring_of[i] = kDropped;
    if (!p.p.allFinite() || (scan.has_time && !std::isfinite(p.dt))) {
      ++rep.removed_invalid;
      continue;
    }
    const float r2 = p.p.squaredNorm();
    if (r2 < min2 || r2 > max2 || insideBox(p.p, cfg)) {
      ++rep.removed_range;
      continue;
    }
    ring_of[i] = static_cast<std::uint16_t>(std::min<int>(p.ring, kMaxRings));  // beyond any sensor: dropped later
    max_ring = std::max<int>(max_ring, p.ring);
    if (first < 0) first = static_cast<long>(i);
  }
  return first;
}

// Beams of the sensor; a corrupt ring field cannot make us allocate 65536 rings (points beyond are dropped).
int ringCount(const LidarScan& scan, int max_valid_ring, const PreprocessConfig& cfg) {
  if (scan.num_beams > 0) return std::min(scan.num_beams, kMaxRings);
  if (!scan.has_ring) return std::clamp(cfg.num_rings, 1, kMaxRings);
  return std::min(max_valid_ring + 1, kMaxRings);
}

// Rings from elevation when the scan lacks them; points on rings beyond the sensor's count dropped.
// counts[r + 1] = points kept on ring r.
void assignRings(const LidarScan& scan, const PreprocessConfig& cfg, int num_rings,
                 std::vector<std::uint16_t>& ring_of, std::vector<int>& counts, PreprocessReport& rep) {
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    if (ring_of[i] == kDropped) continue;
    const int ring = scan.has_ring ? ring_of[i]
                                   : ringFromElevation(scan.points[i].p, num_rings, cfg.min_elevation_deg,
                                                       cfg.max_elevation_deg);
    if (ring >= num_rings) {
      ++rep.removed_range;
      ring_of[i] = kDropped;
      continue;
    }
    ring_of[i] = static_cast<std::uint16_t>(ring);
    ++counts[ring + 1];
  }
}

// Orders of float times as unsigned integers: flip all bits of negatives, the sign bit of the rest. -0 and +0
// compare equal as floats, so both take +0's key.
std::uint32_t timeKey(float dt) {
  std::uint32_t bits;
  const float v = dt == 0.0f ? 0.0f : dt;
  std::memcpy(&bits, &v, sizeof bits);
  return (bits & 0x80000000u) ? ~bits : bits | 0x80000000u;
}

// Stable sort of points [b, e) by time (finite times): an integer sort of (time key, position) pairs, which
// are unique, then one permutation; the same order as std::stable_sort on the points, at a fraction of the
// cost (KITTI rows are not two sorted runs).
void sortByTime(std::vector<LidarPoint>& points, int b, int e, std::vector<std::uint64_t>& keys,
                std::vector<LidarPoint>& scratch) {
  keys.resize(static_cast<std::size_t>(e - b));
  for (int i = b; i < e; ++i)
    keys[static_cast<std::size_t>(i - b)] = (static_cast<std::uint64_t>(timeKey(points[i].dt)) << 32) |
                                            static_cast<std::uint32_t>(i - b);
  std::sort(keys.begin(), keys.end());
  scratch.assign(points.begin() + b, points.begin() + e);
  for (std::size_t k = 0; k < keys.size(); ++k) points[b + k] = scratch[keys[k] & 0xFFFFFFFFu];
}

// Kept points grouped by ring (counting sort, stable) with their times filled in, then in firing order
// inside each ring. One pass over the scan: no intermediate copy of the sweep.
RingCloud groupByRing(const LidarScan& scan, const std::vector<std::uint16_t>& ring_of, std::vector<int> ring_begin,
                      long seam_index, bool clockwise) {
  const int num_rings = static_cast<int>(ring_begin.size()) - 1;
  for (int r = 0; r < num_rings; ++r) ring_begin[r + 1] += ring_begin[r];
  RingCloud cloud;
  cloud.points.resize(static_cast<std::size_t>(ring_begin.back()));
  std::vector<int> next(ring_begin.begin(), ring_begin.end() - 1);
  const float sweep = std::max(scan.sweep_duration, 1e-3f);
  const LidarPoint* seam_point = seam_index >= 0 ? &scan.points[static_cast<std::size_t>(seam_index)] : nullptr;
  const float seam = seam_point ? std::atan2(seam_point->p.y(), seam_point->p.x()) : 0.0f;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    if (ring_of[i] == kDropped) continue;
    LidarPoint& q = cloud.points[static_cast<std::size_t>(next[ring_of[i]]++)];
    q = scan.points[i];
    q.ring = ring_of[i];
    q.dt = scan.has_time ? std::clamp(q.dt, -sweep, 0.0f) : timeFromAzimuth(q.p, seam, sweep, clockwise);
  }
  cloud.ring_begin = std::move(ring_begin);
  std::vector<std::uint64_t> keys;
  std::vector<LidarPoint> scratch;
  const auto by_time = [](const LidarPoint& a, const LidarPoint& b) { return a.dt < b.dt; };
  for (int r = 0; r < num_rings; ++r) {
    auto first = cloud.points.begin() + cloud.ring_begin[r], last = cloud.points.begin() + cloud.ring_begin[r + 1];
    const auto mid = std::is_sorted_until(first, last, by_time);
    if (mid == last) continue;
    // A row that starts mid-sweep is two sorted runs, the second all earlier than the first: rotating them
    // equals the stable sort.
    if (std::is_sorted(mid, last, by_time) && by_time(*(last - 1), *first))
      std::rotate(first, mid, last);
    else
      sortByTime(cloud.points, cloud.ring_begin[r], cloud.ring_begin[r + 1], keys, scratch);
  }
  return cloud;
}

// Neighbours of point i within the radius among [center - window, center + window] of [first, last), counted
// up to `need` (the filter only asks whether there are enough).
inline int neighboursWithin(const RingCloud& c, int i, int first, int last, int center, int window, float radius2,
                            int need) {
  int count = 0;
  const Eigen::Vector3f p = c.points[i].p;
  for (int j = std::max(first, center - window); j <= std::min(last - 1, center + window) && count < need; ++j)
    if (j != i && (c.points[j].p - p).squaredNorm() < radius2) ++count;
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
      const int need = cfg.outlier_min_neighbors;
      int count = neighboursWithin(c, i, c.ring_begin[r], c.ring_begin[r + 1], i, cfg.outlier_window, radius * radius, need);
      for (int side = 0; side < 2 && count < cfg.outlier_min_neighbors; ++side) {
        const int adj = side == 0 ? r - 1 : r + 1;
        if (adj < 0 || adj >= c.numRings() || c.ringSize(adj) == 0) continue;
        int& k = cursor[side];  // last point of the adjacent ring fired no later than point i
        while (k + 1 < c.ring_begin[adj + 1] && c.points[k + 1].dt <= c.points[i].dt) ++k;
        count += neighboursWithin(c, i, c.ring_begin[adj], c.ring_begin[adj + 1], k, cfg.outlier_window,
                                  radius * radius, need - count);
      }
      keep[i] = count >= cfg.outlier_min_neighbors;
    }
  }
  return keep;
}

// Drops the points the radius filter rejects, in place.
void removeOutliers(RingCloud& c, const PreprocessConfig& cfg, PreprocessReport& rep) {
  if (cfg.outlier_min_neighbors <= 0) return;
  const std::vector<char> keep = radiusInliers(c, cfg);
  std::size_t kept = 0;
  for (int r = 0; r < c.numRings(); ++r) {
    const int b = c.ring_begin[r], e = c.ring_begin[r + 1];
    c.ring_begin[r] = static_cast<int>(kept);
    for (int i = b; i < e; ++i) {
      if (keep[i]) c.points[kept++] = c.points[i];
      else ++rep.removed_outlier;
    }
  }
  c.ring_begin.back() = static_cast<int>(kept);
  c.points.resize(kept);
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
  rep.ring_derived = !scan.has_ring;
  rep.time_derived = !scan.has_time;
  std::vector<std::uint16_t> ring_of(scan.points.size());
  int max_ring = 0;
  const long seam_index = markValidPoints(scan, cfg, ring_of, max_ring, rep);
  const int num_rings = ringCount(scan, max_ring, cfg);
  std::vector<int> counts(static_cast<std::size_t>(num_rings) + 1, 0);
  assignRings(scan, cfg, num_rings, ring_of, counts, rep);
  RingCloud cloud = groupByRing(scan, ring_of, std::move(counts), seam_index, cfg.clockwise);
  removeOutliers(cloud, cfg, rep);
  if (report) *report = rep;
  return cloud;
}

std::vector<LidarPoint> voxelDownsample(const std::vector<LidarPoint>& points, float leaf) {
  if (!(leaf > 0.0f) || points.empty()) return points;
  VoxelCentroids grid(leaf, points.size());
  for (const LidarPoint& p : points) grid.add(p);
  return grid.take();
}

}  // namespace adit::features
