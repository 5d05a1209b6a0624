#include "loop/plane_target_cache.hpp"

#include <cstring>

namespace adit {

bool sameNeighbourhood(const CandidateNeighbourhood& a, const CandidateNeighbourhood& b) {
  if (a.clouds.size() != b.clouds.size() || a.T_match_cloud.size() != b.T_match_cloud.size()) return false;
  for (std::size_t i = 0; i < a.T_match_cloud.size(); ++i)  // bit for bit: a moved graph is another submap
    if (std::memcmp(a.T_match_cloud[i].matrix().data(), b.T_match_cloud[i].matrix().data(), sizeof(double) * 16) != 0)
      return false;
  for (std::size_t i = 0; i < a.clouds.size(); ++i) {
    const CompactCloud &x = a.clouds[i], &y = b.clouds[i];
    const float sx = x.step(), sy = y.step();
    if (std::memcmp(&sx, &sy, sizeof(float)) != 0 || x.counts() != y.counts()) return false;
  }
  return true;
}

std::shared_ptr<const PlaneTarget> PlaneTargetCache::target(const CandidateNeighbourhood& neighbourhood,
                                                            const LoopVerifierConfig& config, bool* kept) {
  for (auto it = entries_.begin(); it != entries_.end(); ++it) {
    if (!sameNeighbourhood(it->neighbourhood, neighbourhood)) continue;
    ++hits_;
    if (kept) *kept = true;
    Entry entry = std::move(*it);
    entries_.erase(it);
    entries_.push_front(std::move(entry));
    return entries_.front().target;
  }
  ++builds_;
  if (kept) *kept = false;
  std::shared_ptr<const PlaneTarget> built = candidateTarget(neighbourhood, config);
  if (capacity_ == 0) return built;
  entries_.push_front({neighbourhood, built});
  while (entries_.size() > capacity_) entries_.pop_back();
  return built;
}

}  // namespace adit
