// The last few candidate submaps' ICP targets, for the loop jobs. Consecutive keyframes of a drive often meet
// the same Scan Context candidate (roadway-loop 120 s: 176 verifications of 50 distinct candidates, up to 19
// of one), and the plane target (submap merged, thinned, a normal fitted at every point) was half of a
// verification's cost. A target is reused only for a neighbourhood equal to the one it was built from
// (every cloud's step and counts, every relative pose bit for bit): after the graph moves (a loop closed),
// the same candidate's neighbourhood differs and a new target is built. So a job's result is the same with
// or without the cache. Not thread-safe: the loop jobs run one after the other.
#pragma once

#include "loop/place_match.hpp"

#include <cstddef>
#include <deque>
#include <memory>

namespace adit {

class PlaneTargetCache {
 public:
  // capacity 0: nothing kept (every call builds).
  explicit PlaneTargetCache(std::size_t capacity = 4) : capacity_(capacity) {}

  // The target of this neighbourhood's submap (candidateTarget), built, or kept from an earlier call with an
  // equal neighbourhood (one cache serves one verifier configuration); `kept` (if given) says which.
  std::shared_ptr<const PlaneTarget> target(const CandidateNeighbourhood& neighbourhood, const LoopVerifierConfig& config,
                                            bool* kept = nullptr);

  void clear() { entries_.clear(); }  // frees the targets (~1-2 MB each)
  std::size_t hits() const { return hits_; }
  std::size_t builds() const { return builds_; }

 private:
  struct Entry {
    CandidateNeighbourhood neighbourhood;
    std::shared_ptr<const PlaneTarget> target;
  };
  std::size_t capacity_;
  std::deque<Entry> entries_;  // most recently used first
  std::size_t hits_ = 0, builds_ = 0;
};

// Equal clouds (step and counts) at bitwise equal poses, in the same order.
bool sameNeighbourhood(const CandidateNeighbourhood& a, const CandidateNeighbourhood& b);

}  // namespace adit
