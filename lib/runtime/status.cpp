#include "runtime/status.hpp"

#include <cctype>
#include <cmath>
#include <utility>

namespace adit::runtime {

void PublishedTraffic::add(const std::string& channel, std::size_t bytes) {
  Count& c = window_[channel];
  c.bytes += static_cast<std::int64_t>(bytes);
  c.messages += 1;
}

void PublishedTraffic::report(adit::status_t& status, double window_s) {
  status.num_channels = static_cast<std::int32_t>(window_.size());
  status.channel_names.clear();
  status.channel_bytes_per_s.clear();
  status.channel_messages_per_s.clear();
  for (auto& [channel, count] : window_) {
    status.channel_names.push_back(channel);
    status.channel_bytes_per_s.push_back(window_s > 0 ? static_cast<float>(static_cast<double>(count.bytes) / window_s) : 0.0f);
    status.channel_messages_per_s.push_back(
        window_s > 0 ? static_cast<float>(static_cast<double>(count.messages) / window_s) : 0.0f);
    count = Count{};
  }
}

std::string statusChannel(const std::string& process) {
  std::string out = "STATUS_";
  for (char c : process) out += c == '-' ? '_' : static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

adit::status_t makeStatus(const std::string& process, const Health& health, const TimingWindow& timing,
                          std::int64_t wall_utime, std::int64_t seq, double uptime_s, double rate_hz,
                          double busy, const std::string& state) {
  adit::status_t s;
  s.header.utime = wall_utime;
  s.header.seq = seq;
  s.header.frame_id = "";
  s.process = process;
  s.state = state;
  s.uptime_s = uptime_s;
  s.inputs = health.inputs;
  s.outputs = health.outputs;
  s.drops = health.drops;
  s.errors = health.errors;
  s.proc_ms_p50 = static_cast<float>(timing.quantile(0.5));
  s.proc_ms_p95 = static_cast<float>(timing.quantile(0.95));
  s.proc_ms_max = static_cast<float>(timing.max());
  s.busy_fraction = static_cast<float>(busy);
  s.last_input_utime = health.last_input_utime;
  s.input_rate_hz = static_cast<float>(rate_hz);
  s.num_counters = static_cast<std::int32_t>(health.counters.size());
  for (const auto& kv : health.counters) {
    s.counter_names.push_back(kv.first);
    s.counter_values.push_back(kv.second);
  }
  s.last_error = health.last_error;
  s.num_channels = 0;  // PublishedTraffic::report fills them
  return s;
}

adit::status_t makeStatus(const Node& node, std::int64_t wall_utime, std::int64_t seq, double uptime_s,
                          double rate_hz, double busy, const std::string& state) {
  return makeStatus(node.name(), node.health(), node.timing(), wall_utime, seq, uptime_s, rate_hz, busy, state);
}

void addLatencyCounters(adit::status_t& status, const std::string& name, const LatencySummary& latency) {
  const auto us = [](double ms) { return static_cast<std::int64_t>(std::llround(ms * 1e3)); };
  const std::pair<const char*, std::int64_t> fields[] = {
      {"_p50_us", us(latency.p50_ms)}, {"_p95_us", us(latency.p95_ms)}, {"_p99_us", us(latency.p99_ms)},
      {"_max_us", us(latency.max_ms)}, {"_samples", latency.samples},   {"_unmatched", latency.unmatched}};
  for (const auto& [suffix, value] : fields) {
    status.counter_names.push_back(name + suffix);
    status.counter_values.push_back(value);
  }
  status.num_counters = static_cast<std::int32_t>(status.counter_names.size());
}

void addMemoryCounters(adit::status_t& status, const MemoryUse& memory, const ProcessResources& resources) {
  const std::pair<const char*, std::int64_t> fields[] = {{"memory_resident_kb", memory.resident_kb},
                                                         {"memory_heap_in_use_kb", memory.heap_in_use_kb},
                                                         {"memory_heap_free_kb", memory.heap_free_kb},
                                                         {"memory_anonymous_kb", resources.anonymous_kb},
                                                         {"threads", resources.threads},
                                                         {"open_files", resources.open_files}};
  for (const auto& [name, value] : fields) {
    status.counter_names.push_back(name);
    status.counter_values.push_back(value);
  }
  status.num_counters = static_cast<std::int32_t>(status.counter_names.size());
}

}  // namespace adit::runtime
