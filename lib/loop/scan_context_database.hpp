// Keyframe Scan Contexts and the place query: a KD-tree on the rotation-invariant ring keys proposes the
// nearest keyframes, and the full column-shift distance ranks them.
#pragma once

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
  const ScanContext& context(int index) const { return contexts_[static_cast<std::size_t>(index)]; }

 private:
  struct RingKeyTree;
  void rebuildTree();
  int eligibleCount(int exclude_recent, std::int64_t latest_utime) const;

  int num_candidates_;
  int rebuild_every_;
  std::vector<ScanContext> contexts_;
  std::vector<std::int64_t> utimes_;
  std::unique_ptr<RingKeyTree> tree_;  // over the first tree_size_ entries
  int tree_size_ = 0;
};

}  // namespace adit
