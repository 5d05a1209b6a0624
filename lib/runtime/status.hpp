// Builds the STATUS message of a node.
#pragma once

#include "runtime/allocator.hpp"
#include "runtime/latency.hpp"
#include "runtime/node.hpp"
#include "runtime/resources.hpp"

#include <adit/status_t.hpp>

#include <cstddef>
#include <map>
#include <string>

namespace adit::runtime {

// Bytes and messages a process publishes per channel between two STATUS reports: the bandwidth STATUS shows.
class PublishedTraffic {
 public:
  void add(const std::string& channel, std::size_t bytes);
  // Sets status's channel fields to the rates over window_s (every channel seen so far, silent ones at 0)
  // and starts a new window.
  void report(adit::status_t& status, double window_s);

 private:
  struct Count {
    std::int64_t bytes = 0, messages = 0;
  };
  std::map<std::string, Count> window_;
};

// STATUS_<PROCESS> in capitals, '-' as '_': "loop-closer" -> "STATUS_LOOP_CLOSER".
std::string statusChannel(const std::string& process);

// wall_utime: the report time (monitoring only); rate_hz: inputs per second and busy: share of the time
// spent processing, both over the last window.
adit::status_t makeStatus(const Node& node, std::int64_t wall_utime, std::int64_t seq, double uptime_s,
                          double rate_hz, double busy, const std::string& state);

// Same for a source process (bridge) that has no Node: counters only.
adit::status_t makeStatus(const std::string& process, const Health& health, const TimingWindow& timing,
                          std::int64_t wall_utime, std::int64_t seq, double uptime_s, double rate_hz,
                          double busy, const std::string& state);

// Appends a latency summary to status's named counters, in microseconds: "<name>_p50_us", "_p95_us",
// "_p99_us", "_max_us", and "<name>_samples" (sweeps in the window), "<name>_unmatched" (never completed).
void addLatencyCounters(adit::status_t& status, const std::string& name, const LatencySummary& latency);

// Appends the process's memory (runtime/allocator.hpp) and resources (runtime/resources.hpp), last measured, to
// status's named counters: "memory_resident_kb", "memory_heap_in_use_kb", "memory_heap_free_kb",
// "memory_anonymous_kb", "threads", "open_files".
void addMemoryCounters(adit::status_t& status, const MemoryUse& memory, const ProcessResources& resources);

}  // namespace adit::runtime
