#include "registration/kdtree.hpp"

#include <algorithm>
#include <numeric>

namespace adit {

KdTree3::KdTree3(std::vector<Eigen::Vector3d> points) : points_(std::move(points)) {
  order_.resize(points_.size());
  std::iota(order_.begin(), order_.end(), 0);
  axis_.assign(points_.size(), 0);
  build(0, static_cast<int>(points_.size()));
}

void KdTree3::build(int lo, int hi) {
  if (hi - lo <= 1) return;
  // Split on the axis of largest extent: keeps cells compact for elongated corridor clouds.
  Eigen::Vector3d mn = points_[order_[lo]], mx = mn;
  for (int i = lo + 1; i < hi; ++i) {
    mn = mn.cwiseMin(points_[order_[i]]);
    mx = mx.cwiseMax(points_[order_[i]]);
  }
  int axis = 0;
  (mx - mn).maxCoeff(&axis);
  const int mid = (lo + hi) / 2;
  std::nth_element(order_.begin() + lo, order_.begin() + mid, order_.begin() + hi,
                   [&](int a, int b) { return points_[a][axis] < points_[b][axis]; });
  axis_[mid] = axis;
  build(lo, mid);
  build(mid + 1, hi);
}

int KdTree3::nearest(const Eigen::Vector3d& query, double max_sq_distance, int exclude) const {
  if (points_.empty() || !query.allFinite()) return -1;
  double best_sq = max_sq_distance;
  int best = -1;
  search(0, static_cast<int>(points_.size()), query, exclude, best_sq, best);
  return best;
}

void KdTree3::search(int lo, int hi, const Eigen::Vector3d& q, int exclude, double& best_sq, int& best) const {
  if (lo >= hi) return;
  const int mid = (lo + hi) / 2;
  const int index = order_[mid];
  const double sq = (points_[index] - q).squaredNorm();
  if (sq < best_sq && index != exclude) {
    best_sq = sq;
    best = index;
  }
  if (hi - lo == 1) return;
  const int axis = axis_[mid];
  const double diff = q[axis] - points_[index][axis];
  // Near side first; the far side only if the splitting plane is closer than the best so far.
  if (diff < 0) {
    search(lo, mid, q, exclude, best_sq, best);
    if (diff * diff < best_sq) search(mid + 1, hi, q, exclude, best_sq, best);
  } else {
    search(mid + 1, hi, q, exclude, best_sq, best);
    if (diff * diff < best_sq) search(lo, mid, q, exclude, best_sq, best);
  }
}

std::vector<int> KdTree3::nearestK(const Eigen::Vector3d& query, int k, double max_sq_distance) const {
  std::vector<Candidate> best;
  if (points_.empty() || k <= 0 || !query.allFinite()) return {};
  best.reserve(static_cast<std::size_t>(k) + 1);
  searchK(0, static_cast<int>(points_.size()), query, k, max_sq_distance, best);
  std::vector<int> out;
  out.reserve(best.size());
  for (const Candidate& c : best) out.push_back(c.index);
  return out;
}

void KdTree3::searchK(int lo, int hi, const Eigen::Vector3d& q, int k, double max_sq,
                      std::vector<Candidate>& best) const {
  if (lo >= hi) return;
  const auto bound = [&] { return static_cast<int>(best.size()) < k ? max_sq : best.back().sq; };
  const int mid = (lo + hi) / 2;
  const int index = order_[mid];
  const double sq = (points_[index] - q).squaredNorm();
  if (sq < bound()) {
    // Sorted insert; ties keep the earlier-found point first (deterministic).
    auto pos = std::upper_bound(best.begin(), best.end(), sq, [](double v, const Candidate& c) { return v < c.sq; });
    best.insert(pos, {sq, index});
    if (static_cast<int>(best.size()) > k) best.pop_back();
  }
  if (hi - lo == 1) return;
  const int axis = axis_[mid];
  const double diff = q[axis] - points_[index][axis];
  if (diff < 0) {
    searchK(lo, mid, q, k, max_sq, best);
    if (diff * diff < bound()) searchK(mid + 1, hi, q, k, max_sq, best);
  } else {
    searchK(mid + 1, hi, q, k, max_sq, best);
    if (diff * diff < bound()) searchK(lo, mid, q, k, max_sq, best);
  }
}

}  // namespace adit
