#include "loop/scan_context_database.hpp"

#include "core/byte_codec.hpp"
#include "loop/keep_mask.hpp"
#include "loop/keyframe_codec.hpp"

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
  ring_keys_.push_back(context.ringKey());
  offsets_.push_back(-1);
  utimes_.push_back(utime);
  if (size() - tree_size_ >= rebuild_every_) rebuildTree();
  pageOut();
  return size() - 1;
}

void ScanContextDatabase::retain(const std::vector<bool>& keep) {
  queue_.retain(keep);
  eraseUnkept(contexts_, keep);
  eraseUnkept(ring_keys_, keep);
  eraseUnkept(offsets_, keep);
  eraseUnkept(utimes_, keep);
  contexts_.shrink_to_fit();
  ring_keys_.shrink_to_fit();
  offsets_.shrink_to_fit();
  utimes_.shrink_to_fit();
  tree_.reset();
  tree_size_ = 0;
  if (size() >= rebuild_every_) rebuildTree();
}

ScanContext ScanContextDatabase::context(int index) const {
  ScanContext scratch;
  const ScanContext& c = load(index, scratch);
  return &c == &scratch ? std::move(scratch) : c;
}

const ScanContext& ScanContextDatabase::load(int index, ScanContext& scratch) const {
  const auto i = static_cast<std::size_t>(index);
  if (offsets_[i] < 0) return contexts_[i];
  // A record: its size, then the context as a checkpoint writes it (keyframe_codec.hpp).
  std::uint32_t bytes = 0;
  std::string record;
  constexpr std::uint32_t kMaxRecord = 1u << 24;  // a 1000 x 1000 context (the codec's limit) is 4 MB
  if (file_.read(offsets_[i], &bytes, sizeof bytes) && bytes <= kMaxRecord) {
    record.resize(bytes);
    if (file_.read(offsets_[i] + static_cast<std::int64_t>(sizeof bytes), record.data(), record.size())) {
      ByteReader r(record);
      if (std::optional<ScanContext> read = getScanContext(r); read && r.ok() && r.atEnd()) {
        scratch = std::move(*read);
        return scratch;
      }
    }
  }
  ++read_errors_;
  scratch = ScanContext();
  return scratch;
}

void ScanContextDatabase::pageTo(const std::string& path, std::size_t resident) {
  PageFile file = PageFile::create(path, "Scan Context");
  for (int i = 0; i < size(); ++i) {  // contexts paged to an earlier file come back first
    if (offsets_[static_cast<std::size_t>(i)] < 0) continue;
    contexts_[static_cast<std::size_t>(i)] = context(i);
    offsets_[static_cast<std::size_t>(i)] = -1;
  }
  file_ = std::move(file);
  queue_.restart(resident);
  pageOut();
}

void ScanContextDatabase::pageOut() {
  if (file_.isOpen()) queue_.pageOut(contexts_.size(), [this](std::size_t i) { return pageOne(i); });
}

// One record: its size, then the context as a checkpoint writes it.
PagingQueue::Outcome ScanContextDatabase::pageOne(std::size_t i) {
  if (contexts_[i].empty() || offsets_[i] >= 0) return PagingQueue::Outcome::kNothingToPage;
  ByteWriter w;
  putScanContext(w, contexts_[i]);
  const auto bytes = static_cast<std::uint32_t>(w.bytes().size());
  std::string record(reinterpret_cast<const char*>(&bytes), sizeof bytes);
  record += w.bytes();
  const std::int64_t offset = file_.append(record.data(), record.size());
  if (offset < 0) return PagingQueue::Outcome::kFailed;  // kept in memory; the next add tries again
  offsets_[i] = offset;
  contexts_[i] = ScanContext();
  return PagingQueue::Outcome::kPaged;
}

std::size_t ScanContextDatabase::residentBytes() const {
  std::size_t bytes = contexts_.capacity() * sizeof(ScanContext) + ring_keys_.capacity() * sizeof(Eigen::VectorXf) +
                      (offsets_.capacity() + utimes_.capacity()) * sizeof(std::int64_t);
  for (std::size_t i = 0; i < contexts_.size(); ++i) {
    const ScanContext& c = contexts_[i];
    bytes += static_cast<std::size_t>(c.descriptor().size() + c.ringKey().size() + c.sectorKey().size()) * sizeof(float);
    bytes += static_cast<std::size_t>(ring_keys_[i].size()) * sizeof(float);
  }
  return bytes;
}

void ScanContextDatabase::rebuildTree() {
  std::size_t dim = 0;  // of the first real context (a revisit keyframe's is empty)
  for (const Eigen::VectorXf& key : ring_keys_)
    if (key.size() > 0) {
      dim = static_cast<std::size_t>(key.size());
      break;
    }
  std::vector<float> keys;
  keys.reserve(ring_keys_.size() * dim);
  for (const Eigen::VectorXf& key : ring_keys_) {
    for (std::size_t d = 0; d < dim; ++d)
      keys.push_back(static_cast<std::size_t>(key.size()) == dim ? key[static_cast<Eigen::Index>(d)] : 0.0f);
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
    const Eigen::VectorXf& other = ring_keys_[static_cast<std::size_t>(i)];
    if (other.size() != key.size()) continue;
    near.emplace_back((other - key).squaredNorm(), i);
  }
  std::sort(near.begin(), near.end());  // by distance, ties by index: deterministic
  if (static_cast<int>(near.size()) > num_candidates_) near.resize(static_cast<std::size_t>(num_candidates_));

  ScanContext scratch;
  for (const auto& [sq, index] : near) {
    const ScanContext& other = load(index, scratch);
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
