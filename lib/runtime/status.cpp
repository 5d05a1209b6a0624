#include "runtime/status.hpp"

#include <cctype>

namespace adit::runtime {

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
  return s;
}

adit::status_t makeStatus(const Node& node, std::int64_t wall_utime, std::int64_t seq, double uptime_s,
                          double rate_hz, double busy, const std::string& state) {
  return makeStatus(node.name(), node.health(), node.timing(), wall_utime, seq, uptime_s, rate_hz, busy, state);
}

}  // namespace adit::runtime
