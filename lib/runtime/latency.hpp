// Latency from a sweep's arrival on the bus to the output that completes it (e.g. LIDAR_POINTS to
// ODOM_MAPPED), matched by sensor time: every stage keeps the sweep's header.utime. Wall-clock times in,
// milliseconds out; monitoring only (STATUS, benchmarks), never an input to a stage.
#pragma once

#include "runtime/health.hpp"

#include <cstddef>
#include <cstdint>
#include <map>

namespace adit::runtime {

struct LatencySummary {
  std::int64_t samples = 0;    // completed sweeps in the window
  std::int64_t unmatched = 0;  // arrivals that never completed (dropped on the way), whole run
  double p50_ms = 0, p95_ms = 0, p99_ms = 0, max_ms = 0;
};

class LatencyTracker {
 public:
  // window: completed sweeps the quantiles cover (the newest ones); pending: arrivals remembered while
  // their output is outstanding (older ones are given up as unmatched).
  explicit LatencyTracker(std::size_t window = 3000, std::size_t pending = 256);
  // A sweep stamped `utime` arrived at wall time `wall_us` (a repeated arrival keeps the first stamp).
  void arrived(std::int64_t utime, std::int64_t wall_us);
  // Its output was published at `wall_us`: one sample if its arrival is known. Arrivals older than `utime`
  // still waiting will not complete (outputs come in sensor-time order): counted as unmatched.
  bool completed(std::int64_t utime, std::int64_t wall_us);
  LatencySummary summary() const;

 private:
  TimingWindow latency_ms_;
  std::size_t pending_capacity_;
  std::map<std::int64_t, std::int64_t> pending_;  // utime -> arrival wall time
  std::int64_t unmatched_ = 0;
};

}  // namespace adit::runtime
