#include "pipeline/live_status.hpp"

#include "msg/encode.hpp"
#include "runtime/lcm_log.hpp"

namespace adit::pipeline {

std::map<std::string, adit::status_t> lastStatusByProcess(const std::string& log_path) {
  runtime::LogReader log(log_path);
  std::map<std::string, adit::status_t> last;
  runtime::LogEvent event;
  while (log.next(event)) {
    if (event.channel.rfind("STATUS_", 0) != 0) continue;
    adit::status_t status;
    if (status.decode(event.data.data(), 0, static_cast<int>(event.data.size())) < 0) continue;
    last[status.process] = std::move(status);
  }
  return last;
}

std::int64_t statusCounter(const adit::status_t& status, const std::string& name, std::int64_t fallback) {
  for (std::size_t i = 0; i < status.counter_names.size() && i < status.counter_values.size(); ++i)
    if (status.counter_names[i] == name) return status.counter_values[i];
  return fallback;
}

std::vector<BenchFigure> liveFigures(const std::map<std::string, adit::status_t>& last_status) {
  std::vector<BenchFigure> figures;
  if (const auto mapper = last_status.find("mapper"); mapper != last_status.end()) {
    const adit::status_t& s = mapper->second;
    for (const char* q : {"p50", "p95", "p99", "max"}) {
      const std::int64_t us = statusCounter(s, std::string("points_to_mapped_") + q + "_us");
      if (us >= 0) figures.push_back({std::string("latency_points_to_mapped.") + q + "_ms", us * 1e-3, "ms", false});
    }
    const std::int64_t n = statusCounter(s, "points_to_mapped_samples");
    if (n >= 0) figures.push_back({"latency_points_to_mapped.samples", static_cast<double>(n), "sweeps", true});
    const std::int64_t lost = statusCounter(s, "points_to_mapped_unmatched");
    if (lost >= 0) figures.push_back({"latency_points_to_mapped.unmatched", static_cast<double>(lost), "sweeps", false});
  }
  for (const auto& [process, s] : last_status) {
    if (s.inputs == 0) continue;  // a source (the simulator): no stage timing
    figures.push_back({process + ".proc_p50_ms", s.proc_ms_p50, "ms", false});
    figures.push_back({process + ".proc_p95_ms", s.proc_ms_p95, "ms", false});
    figures.push_back({process + ".inputs", static_cast<double>(s.inputs), "", true});
  }
  return figures;
}

}  // namespace adit::pipeline
