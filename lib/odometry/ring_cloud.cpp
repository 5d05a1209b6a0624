#include "odometry/ring_cloud.hpp"

#include "registration/k_best.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace adit {
namespace {

constexpr float kPi = static_cast<float>(M_PI);

// Azimuth difference (in [0, pi]) from which every point of a ring is at least sqrt(bound_sq) from a query
// at horizontal range h: the half-plane of an azimuth d away is h sin(d) from it, and h beyond a right angle
// (its edge, the vertical axis). So stop from asin(need) on, need = bound / h, if need <= 1. asin(x) <= x +
// (pi/2 - 1) x^3 on [0, 1] (equal at 1; the series' x^3 coefficient is 1/6) stands in for it without a
// trigonometric call: a walk stops a little later, never early; margins cover float rounding.
float stopAzimuth(float h, float bound_sq) {
  const float need = (std::sqrt(bound_sq) + 1e-4f) / (0.999f * h);
  if (!(need <= 1.0f)) return std::numeric_limits<float>::infinity();
  return (need + (0.5f * kPi - 1.0f) * need * need * need) * (1.0f + 1e-5f) + 1e-6f;
}

}  // namespace

RingIndexedCloud::RingIndexedCloud(const std::vector<LidarPoint>& points) {
  std::vector<Eigen::Vector3d> xyz;
  xyz.reserve(points.size());
  rings_.reserve(points.size());
  for (const LidarPoint& p : points) {
    if (!p.p.allFinite()) continue;
    xyz.push_back(p.p.cast<double>());
    rings_.push_back(p.ring);
  }
  // Only the rings that hold points are kept (a corrupt 16-bit ring number costs at most a 64k-entry table
  // for this build, not a ring structure per number), each as its (azimuth, index) pairs sorted (ties by
  // index: deterministic).
  const auto [lo, hi] = rings_.empty() ? std::pair<int, int>{0, -1}
                                       : std::pair<int, int>{*std::min_element(rings_.begin(), rings_.end()),
                                                             *std::max_element(rings_.begin(), rings_.end())};
  std::vector<int> slot(static_cast<std::size_t>(hi - lo + 1), -1);  // ring number - lo -> ring kept
  for (const int r : rings_) slot[static_cast<std::size_t>(r - lo)] = 0;
  for (std::size_t k = 0; k < slot.size(); ++k) {
    if (slot[k] < 0) continue;
    slot[k] = static_cast<int>(ring_numbers_.size());
    ring_numbers_.push_back(lo + static_cast<int>(k));
  }
  std::vector<std::vector<std::pair<float, int>>> order(ring_numbers_.size());
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    const Eigen::Vector3f p = xyz[i].cast<float>();
    order[static_cast<std::size_t>(slot[static_cast<std::size_t>(rings_[i] - lo)])].push_back({std::atan2(p.y(), p.x()), static_cast<int>(i)});
  }
  by_ring_.resize(order.size());
  for (std::size_t r = 0; r < order.size(); ++r) {
    std::sort(order[r].begin(), order[r].end());
    Ring& ring = by_ring_[r];
    ring.azimuth.reserve(order[r].size());
    ring.xyz.reserve(order[r].size());
    ring.to_global.reserve(order[r].size());
    for (const auto& [azimuth, i] : order[r]) {
      ring.azimuth.push_back(azimuth);
      ring.xyz.push_back(xyz[static_cast<std::size_t>(i)].cast<float>());
      ring.to_global.push_back(i);
    }
  }
  all_ = KdTree3(std::move(xyz));
}

const RingIndexedCloud::Ring* RingIndexedCloud::findRing(int ring) const {
  if (ring_numbers_.empty()) return nullptr;
  // Rings usually run without gaps from the first: look there before searching.
  const long guess = static_cast<long>(ring) - ring_numbers_.front();
  if (guess >= 0 && guess < static_cast<long>(ring_numbers_.size()) && ring_numbers_[static_cast<std::size_t>(guess)] == ring)
    return &by_ring_[static_cast<std::size_t>(guess)];
  const auto it = std::lower_bound(ring_numbers_.begin(), ring_numbers_.end(), ring);
  if (it == ring_numbers_.end() || *it != ring) return nullptr;
  return &by_ring_[static_cast<std::size_t>(it - ring_numbers_.begin())];
}

RingIndexedCloud::RingQuery::RingQuery(const Eigen::Vector3d& query)
    : q(query.cast<float>()), h(std::sqrt(q.x() * q.x() + q.y() * q.y())), azimuth(std::atan2(q.y(), q.x())),
      finite(query.allFinite()) {}

// Walks outward from the query's azimuth both ways, nearer azimuth first, and stops where the azimuth alone
// puts every remaining point beyond the k-th best (or the bound).
int RingIndexedCloud::searchRing(const Ring& ring, const RingQuery& query, int k, float max_sq, int exclude,
                                 float* dists, int* indices) const {
  const Eigen::Vector3f& q = query.q;
  const float h = query.h, aq = query.azimuth;
  const int n = static_cast<int>(ring.azimuth.size());
  const int start = static_cast<int>(std::lower_bound(ring.azimuth.begin(), ring.azimuth.end(), aq) - ring.azimuth.begin());
  const auto gap = [&](int pos) {  // |azimuth difference| in [0, pi]
    const float d = std::fabs(ring.azimuth[static_cast<std::size_t>(pos)] - aq);
    return d > kPi ? 2.0f * kPi - d : d;
  };
  int count = 0;
  const auto worst = [&] { return count < k ? max_sq : dists[k - 1]; };
  float stop = stopAzimuth(h, max_sq);
  int right = start == n ? 0 : start, left = start == 0 ? n - 1 : start - 1;
  for (int visited = 0; visited < n; ++visited) {
    const float gr = gap(right), gl = gap(left);
    const bool take_right = gr <= gl;
    if ((take_right ? gr : gl) >= stop) break;  // every point left is at least as far as the k-th best
    const int pos = take_right ? right : left;
    if (take_right) right = right + 1 == n ? 0 : right + 1;
    else left = left == 0 ? n - 1 : left - 1;
    const int global = ring.to_global[static_cast<std::size_t>(pos)];
    const float dist = treeSquaredDistance(q, ring.xyz[static_cast<std::size_t>(pos)]);
    if (!(dist < worst()) || global == exclude) continue;
    insertKBest(dist, global, k, count, dists, indices);
    if (count == k) stop = stopAzimuth(h, dists[k - 1]);
  }
  return count;
}

int RingIndexedCloud::nearest(const Eigen::Vector3d& q, double max_sq_distance) const {
  return all_.nearest(q, max_sq_distance);
}

int RingIndexedCloud::nearestInRing(int ring, const RingQuery& q, double max_sq_distance, int exclude) const {
  const Ring* r = findRing(ring);
  if (!r || !q.finite) return -1;
  float dist;
  int index;
  return searchRing(*r, q, 1, static_cast<float>(max_sq_distance), exclude, &dist, &index) > 0 ? index : -1;
}

void RingIndexedCloud::nearestKInRing(int ring, const RingQuery& q, int k, double max_sq_distance,
                                      std::vector<int>& out) const {
  out.clear();
  const Ring* r = findRing(ring);
  if (!r || k <= 0 || !q.finite) return;
  thread_local std::vector<float> dists;
  thread_local std::vector<int> indices;
  dists.resize(static_cast<std::size_t>(k));
  indices.resize(static_cast<std::size_t>(k));
  const int count = searchRing(*r, q, k, static_cast<float>(max_sq_distance), -1, dists.data(), indices.data());
  out.assign(indices.begin(), indices.begin() + count);
}

int RingIndexedCloud::nearestInNeighbourRings(int ring, int window, const Eigen::Vector3d& q,
                                              double max_sq_distance) const {
  const RingQuery query(q);
  int best = -1;
  double best_sq = max_sq_distance;
  for (int r = ring - window; r <= ring + window; ++r) {
    if (r == ring) continue;
    const int i = nearestInRing(r, query, best_sq, -1);
    if (i < 0) continue;
    best = i;
    best_sq = (point(best) - q).squaredNorm();
  }
  return best;
}

}  // namespace adit
