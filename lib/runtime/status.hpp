// Builds the STATUS message of a node.
#pragma once

#include "runtime/node.hpp"

#include <adit/status_t.hpp>

namespace adit::runtime {

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

}  // namespace adit::runtime
