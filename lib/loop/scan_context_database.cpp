#include "loop/scan_context_database.hpp"

#include "loop/keep_mask.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

namespace adit {

// A snapshot of the ring keys (row-major, n x dim) and a nanoflann index over it.
struct ScanContextDatabase::RingKeyTree {
  std::vector<float> keys;
  std::size_t dim = 0;

  std::size_t kdtree_get_point_count() const { return dim == 0 ? 0 : keys.size() / dim; }
  float kdtree_get_pt(std::size_t i, std::size_t d) const { return keys[i * dim + d]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const { return false; }

  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, RingKeyTree>, RingKeyTree,
                                                    -1, std::uint32_t>;
  std::unique_ptr<Index> index;

  RingKeyTree(std::vector<float> k, std::size_t d) : keys(std::move(k)), dim(d) {
    index = std::make_unique<Index>(static_cast<int>(dim), *this, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  }
};

ScanContextDatabase::ScanContextDatabase(int num_candidates, int rebuild_every)
    : num_candidates_(std::max(1, num_candidates)), rebuild_every_(std::max(1, rebuild_every)) {}
ScanContextDatabase::~ScanContextDatabase() = default;
ScanContextDatabase::ScanContextDatabase(ScanContextDatabase&&) noexcept = default;
ScanContextDatabase& ScanContextDatabase::operator=(ScanContextDatabase&&) noexcept = default;

int ScanContextDatabase::add(const ScanContext& context, std::int64_t utime) {
  contexts_.push_back(context);
  utimes_.push_back(utime);
  if (size() - tree_size_ >= rebuild_every_) rebuildTree();
  return size() - 1;
}

void ScanContextDatabase::retain(const std::vector<bool>& keep) {
  eraseUnkept(contexts_, keep);
  eraseUnkept(utimes_, keep);
  contexts_.shrink_to_fit();
  utimes_.shrink_to_fit();
  tree_.reset();
  tree_size_ = 0;
  if (size() >= rebuild_every_) rebuildTree();
}

void ScanContextDatabase::rebuildTree() {
  std::size_t dim = 0;  // of the first real context (a revisit keyframe's is empty)
  for (const ScanContext& c : contexts_)
    if (!c.empty()) {
      dim = static_cast<std::size_t>(c.ringKey().size());
      break;
    }
  std::vector<float> keys;
  keys.reserve(contexts_.size() * dim);
  for (const ScanContext& c : contexts_) {
    for (std::size_t d = 0; d < dim; ++d)
      keys.push_back(static_cast<std::size_t>(c.ringKey().size()) == dim ? c.ringKey()[static_cast<Eigen::Index>(d)] : 0.0f);
  }
  tree_ = std::make_unique<RingKeyTree>(std::move(keys), dim);
  tree_size_ = size();
}

int ScanContextDatabase::eligibleCount(int exclude_recent, std::int64_t latest_utime) const {
  const int by_count = size() - std::max(0, exclude_recent);
  const int by_time = static_cast<int>(std::upper_bound(utimes_.begin(), utimes_.end(), latest_utime) - utimes_.begin());
  return std::max(0, std::min(by_count, by_time));
}

std::vector<ScanContextCandidate> ScanContextDatabase::query(const ScanContext& context, int exclude_recent,
                                                             std::int64_t latest_utime) const {
  std::vector<ScanContextCandidate> out;
  const int eligible = eligibleCount(exclude_recent, latest_utime);
  if (eligible == 0 || context.empty()) return out;
  const Eigen::VectorXf& key = context.ringKey();

  // Ring-key neighbours: from the tree (asking for extra ones to make up for excluded entries) plus a linear
  // scan of the entries added since the last rebuild.
  std::vector<std::pair<float, int>> near;  // (squared ring-key distance, index)
  if (tree_ && tree_->dim == static_cast<std::size_t>(key.size())) {
    const int excluded_in_tree = std::max(0, tree_size_ - eligible);
    const std::size_t k = static_cast<std::size_t>(std::min(tree_size_, num_candidates_ + excluded_in_tree));
    std::vector<std::uint32_t> indices(k);
    std::vector<float> sq(k);
    const std::size_t found = tree_->index->knnSearch(key.data(), k, indices.data(), sq.data());
    for (std::size_t i = 0; i < found; ++i)
      if (static_cast<int>(indices[i]) < eligible) near.emplace_back(sq[i], static_cast<int>(indices[i]));
  }
  const int linear_from = tree_ && tree_->dim == static_cast<std::size_t>(key.size()) ? tree_size_ : 0;
  for (int i = linear_from; i < eligible; ++i) {
    const Eigen::VectorXf& other = contexts_[static_cast<std::size_t>(i)].ringKey();
    if (other.size() != key.size()) continue;
    near.emplace_back((other - key).squaredNorm(), i);
  }
  std::sort(near.begin(), near.end());  // by distance, ties by index: deterministic
  if (static_cast<int>(near.size()) > num_candidates_) near.resize(static_cast<std::size_t>(num_candidates_));

  for (const auto& [sq, index] : near) {
    const ScanContext& other = contexts_[static_cast<std::size_t>(index)];
    if (other.empty()) continue;
    ScanContextCandidate c;
    c.index = index;
    std::tie(c.distance, c.shift) = context.distance(other);
    c.yaw = yawOfShift(c.shift, context.sectors());
    c.ring_key_distance = std::sqrt(static_cast<double>(sq));
    out.push_back(c);
  }
  std::sort(out.begin(), out.end(), [](const ScanContextCandidate& a, const ScanContextCandidate& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.index < b.index;
  });
  return out;
}

}  // namespace adit
