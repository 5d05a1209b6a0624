#include "runtime/latency.hpp"

#include <iterator>

namespace adit::runtime {

LatencyTracker::LatencyTracker(std::size_t window, std::size_t pending)
    : latency_ms_(window > 0 ? window : 1), pending_capacity_(pending > 0 ? pending : 1) {}

void LatencyTracker::arrived(std::int64_t utime, std::int64_t wall_us) {
  pending_.emplace(utime, wall_us);
  while (pending_.size() > pending_capacity_) {
    pending_.erase(pending_.begin());
    ++unmatched_;
  }
}

bool LatencyTracker::completed(std::int64_t utime, std::int64_t wall_us) {
  const auto it = pending_.find(utime);
  if (it == pending_.end()) return false;
  latency_ms_.add(static_cast<double>(wall_us - it->second) * 1e-3);
  unmatched_ += static_cast<std::int64_t>(std::distance(pending_.begin(), it));
  pending_.erase(pending_.begin(), std::next(it));
  return true;
}

LatencySummary LatencyTracker::summary() const {
  LatencySummary s;
  s.samples = static_cast<std::int64_t>(latency_ms_.size());
  s.unmatched = unmatched_;
  s.p50_ms = latency_ms_.quantile(0.50);
  s.p95_ms = latency_ms_.quantile(0.95);
  s.p99_ms = latency_ms_.quantile(0.99);
  s.max_ms = latency_ms_.max();
  return s;
}

}  // namespace adit::runtime
