// Keyframe Scan Contexts and the place query: a KD-tree on the rotation-invariant ring keys proposes the
// nearest keyframes, and the full column-shift distance ranks them. A live process pages the descriptors of all
// but the newest entries to a file (pageTo): only the ring keys stay in memory, and a candidate's descriptor is
// read back to rank it, which gives the same context (ScanContext::fromDescriptor), so no result changes.
#pragma once

#include "loop/page_file.hpp"
#include "loop/scan_context.hpp"

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace adit {

struct ScanContextCandidate {
  int index = -1;                 // keyframe index (order of add())
  double distance = 1.0;          // Scan Context distance in [0, 1]
  int shift = 0;                  // column shift: query = Rz(yaw) * candidate
  double yaw = 0.0;               // rad, yawOfShift(shift)
  double ring_key_distance = 0.0; // Euclidean distance of the ring keys
};

class ScanContextDatabase {
 public:
  // num_candidates: ring-key nearest neighbours ranked by the full distance per query (SC-A-LOAM uses 10).
  // rebuild_every: the KD-tree is rebuilt after this many additions; newer entries are searched linearly.
  explicit ScanContextDatabase(int num_candidates = 10, int rebuild_every = 50);
  ~ScanContextDatabase();
  ScanContextDatabase(ScanContextDatabase&&) noexcept;
  ScanContextDatabase& operator=(ScanContextDatabase&&) noexcept;
  ScanContextDatabase(const ScanContextDatabase&) = delete;
  ScanContextDatabase& operator=(const ScanContextDatabase&) = delete;

  // Adds a keyframe's context; returns its index. utime orders the time-based exclusion (non-decreasing).
  int add(const ScanContext& context, std::int64_t utime);

  // Candidates sorted by (distance, index), at most num_candidates. Excluded: the `exclude_recent` newest
  // entries and every entry with utime > latest_utime. Empty contexts never match.
  std::vector<ScanContextCandidate> query(
      const ScanContext& context, int exclude_recent,
      std::int64_t latest_utime = std::numeric_limits<std::int64_t>::max()) const;

  // Only the entries with keep[i] stay, renumbered in order (keyframes merged out of the graph).
  void retain(const std::vector<bool>& keep);

  int size() const { return static_cast<int>(contexts_.size()); }
  // Entry `index`'s context, from memory or the page file (an unreadable page gives an empty context, which
  // never matches, counted in readErrors()).
  ScanContext context(int index) const;

  // Pages the descriptors of every entry but the newest `resident` out to `path`, now and as entries are added
  // (see PageFile). Throws std::runtime_error if the file cannot be created; a failed write keeps the entry in
  // memory and is counted (pageErrors()).
  void pageTo(const std::string& path, std::size_t resident);
  std::size_t residentBytes() const;  // contexts and ring keys in memory
  std::size_t pagedContexts() const { return queue_.paged(); }
  std::size_t pageErrors() const { return queue_.errors(); }
  std::size_t readErrors() const { return read_errors_; }

 private:
  struct RingKeyTree;
  void rebuildTree();
  void pageOut();
  PagingQueue::Outcome pageOne(std::size_t index);
  int eligibleCount(int exclude_recent, std::int64_t latest_utime) const;
  // The context of entry `index` (empty if it has none): in memory, or read into `scratch`.
  const ScanContext& load(int index, ScanContext& scratch) const;

  int num_candidates_;
  int rebuild_every_;
  std::vector<ScanContext> contexts_;  // a paged entry's is empty: its ring key and offset say where it is
  std::vector<Eigen::VectorXf> ring_keys_;  // of every entry, paged or not
  std::vector<std::int64_t> offsets_;       // in the page file, or -1
  std::vector<std::int64_t> utimes_;
  PageFile file_;
  PagingQueue queue_;
  mutable std::size_t read_errors_ = 0;
  std::unique_ptr<RingKeyTree> tree_;  // over the first tree_size_ entries
  int tree_size_ = 0;
};

}  // namespace adit
