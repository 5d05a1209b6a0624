#include "registration/kdtree.hpp"

#include "registration/k_best.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace adit {
namespace {

struct PointsAdaptor {
  const std::vector<Eigen::Vector3f>& points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(std::uint32_t i, std::size_t dim) const { return points[i][static_cast<Eigen::Index>(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointsAdaptor, float>, PointsAdaptor, 3,
                                                 std::uint32_t>;

// The k best below a bound, skipping one index: nanoflann's result-set interface. The search prunes with
// worstDist(), so the bound also makes it faster.
class BoundedKnn {
 public:
  BoundedKnn(int k, float max_sq, std::int64_t exclude, float* dists, std::uint32_t* indices)
      : k_(k), max_sq_(max_sq), exclude_(exclude), dists_(dists), indices_(indices) {}
  std::size_t size() const { return static_cast<std::size_t>(count_); }
  bool full() const { return count_ == k_; }
  float worstDist() const { return count_ < k_ ? max_sq_ : dists_[k_ - 1]; }
  bool addPoint(float dist, std::uint32_t index) {
    if (!(dist < worstDist()) || static_cast<std::int64_t>(index) == exclude_) return true;
    insertKBest(dist, index, k_, count_, dists_, indices_);
    return true;
  }

 private:
  int k_;
  float max_sq_;
  std::int64_t exclude_;
  float* dists_;
  std::uint32_t* indices_;
  int count_ = 0;
};

}  // namespace

// Points per leaf. Searches are exact, so this moves only cost: a sweep's trees are built once and queried a
// few thousand times, and the build was the larger part (16 measured cheaper than 8 in a replay; 12 and 32 were
// not told apart from 16 on the same machine, see docs/measurements.md, "Speed").
constexpr std::size_t kLeafSize = 16;

struct KdTree3::Index {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3f> coords;  // what the tree searches: half the bytes of the doubles
  PointsAdaptor adaptor{coords};
  Tree tree{3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize)};
  explicit Index(std::vector<Eigen::Vector3d> p) : points(std::move(p)) {
    coords.reserve(points.size());
    for (const Eigen::Vector3d& q : points) coords.push_back(q.cast<float>());
    tree.buildIndex();
  }
};

KdTree3::KdTree3(std::vector<Eigen::Vector3d> points) {
  if (!points.empty()) index_ = std::make_shared<const Index>(std::move(points));
}

const std::vector<Eigen::Vector3d>& KdTree3::points() const { return index_->points; }

int KdTree3::nearest(const Eigen::Vector3d& query, double max_sq_distance, int exclude) const {
  if (!index_ || !query.allFinite()) return -1;
  float dist = 0.0f;
  std::uint32_t index = 0;
  BoundedKnn result(1, static_cast<float>(max_sq_distance), exclude, &dist, &index);
  const Eigen::Vector3f q = query.cast<float>();
  index_->tree.findNeighbors(result, q.data(), nanoflann::SearchParams(32, 0.0f, false));
  return result.size() > 0 ? static_cast<int>(index) : -1;
}

int KdTree3::nearest(const Eigen::Vector3d& query, double max_sq_distance, NearestMemo& memo) const {
  if (!index_ || !query.allFinite()) return -1;
  const Eigen::Vector3f q = query.cast<float>();
  const auto max_sq = static_cast<float>(max_sq_distance);
  if (memo.index >= 0 && (q - memo.at).norm() < memo.reach) {
    // Still the nearest of all points: the tree would return it if it is within the bound, else nothing.
    const float dist = treeSquaredDistance(q, index_->coords[static_cast<std::size_t>(memo.index)]);
    return dist < max_sq ? memo.index : -1;
  }
  // The two nearest: the first is the one-nearest search's (the same traversal, ties kept in the order met);
  // the second, or the bound when there is none, bounds every other point.
  float dists[2];
  std::uint32_t indices[2];
  BoundedKnn result(2, max_sq, -1, dists, indices);
  index_->tree.findNeighbors(result, q.data(), nanoflann::SearchParams(32, 0.0f, false));
  if (result.size() == 0) {
    memo.index = -1;
    return -1;
  }
  const float others = result.size() > 1 ? dists[1] : max_sq;
  memo.at = q;
  memo.index = static_cast<int>(indices[0]);
  // 0.1 mm below the exact half gap: float distances and the move are computed to ~1e-6 m here.
  memo.reach = 0.5f * (std::sqrt(others) - std::sqrt(dists[0])) - 1e-4f;
  return memo.index;
}

void KdTree3::nearestK(const Eigen::Vector3d& query, int k, double max_sq_distance, std::vector<int>& out) const {
  out.clear();
  if (!index_ || k <= 0 || !query.allFinite()) return;
  constexpr int kStack = 64;
  float dists[kStack];
  std::uint32_t indices[kStack];
  std::vector<float> more_dists;
  std::vector<std::uint32_t> more_indices;
  float* d = dists;
  std::uint32_t* idx = indices;
  if (k > kStack) {
    more_dists.resize(static_cast<std::size_t>(k));
    more_indices.resize(static_cast<std::size_t>(k));
    d = more_dists.data();
    idx = more_indices.data();
  }
  BoundedKnn result(k, static_cast<float>(max_sq_distance), -1, d, idx);
  const Eigen::Vector3f q = query.cast<float>();
  index_->tree.findNeighbors(result, q.data(), nanoflann::SearchParams(32, 0.0f, false));
  for (std::size_t i = 0; i < result.size(); ++i) out.push_back(static_cast<int>(idx[i]));
}

}  // namespace adit
