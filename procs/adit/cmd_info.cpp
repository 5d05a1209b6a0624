// adit info <log>: what an LCM log holds, per channel: message count, type, time span, rate, size per message
// and bandwidth (MB/s over the whole log's span, i.e. what the channel costs the bus and the disk), and the
// whole log's rate.
#include "commands.hpp"

#include "msg/type_name.hpp"
#include "runtime/lcm_log.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>

namespace {

struct ChannelStats {
  std::int64_t count = 0, bytes = 0, first = 0, last = 0;
  std::string type;
};

}  // namespace

void registerInfoCommand(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("info", "Summarise an LCM log: messages, type, time span and rate per channel");
  cmd->add_option("log", *path, "LCM log")->required()->check(CLI::ExistingFile);
  cmd->callback([path] {
    adit::runtime::LogReader reader(*path);
    std::map<std::string, ChannelStats> channels;
    adit::runtime::LogEvent e;
    while (reader.next(e)) {
      ChannelStats& s = channels[e.channel];
      if (s.count++ == 0) {
        s.first = e.timestamp;
        s.type = adit::msg::messageTypeName(e.data.data(), e.data.size());
      }
      s.last = e.timestamp;
      s.bytes += static_cast<std::int64_t>(e.data.size());
    }
    if (channels.empty())
      throw std::runtime_error("'" + *path + "' holds no LCM event (empty, or not an LCM log)");
    // Bandwidth over the log's span (first to last event of any channel): a sparse channel's share of the run.
    std::int64_t first = 0, last = 0, total = 0;
    for (const auto& [name, s] : channels) {
      first = total == 0 ? s.first : std::min(first, s.first);
      last = std::max(last, s.last);
      total += s.bytes;
    }
    const double log_span = static_cast<double>(last - first) * 1e-6;
    const auto perSecond = [&](std::int64_t bytes) { return log_span > 0 ? static_cast<double>(bytes) / 1e6 / log_span : 0.0; };
    fmt::print("{:<24} {:>8} {:<16} {:>10} {:>9} {:>10} {:>10} {:>9}\n", "channel", "messages", "type", "span_s",
               "rate_hz", "MB", "kB/msg", "MB/s");
    for (const auto& [name, s] : channels) {
      const double span = static_cast<double>(s.last - s.first) * 1e-6;
      fmt::print("{:<24} {:>8} {:<16} {:>10.3f} {:>9.2f} {:>10.2f} {:>10.2f} {:>9.3f}\n", name, s.count,
                 s.type.empty() ? "?" : s.type, span, span > 0 ? static_cast<double>(s.count - 1) / span : 0.0,
                 static_cast<double>(s.bytes) / 1e6, static_cast<double>(s.bytes) / 1e3 / static_cast<double>(s.count),
                 perSecond(s.bytes));
    }
    fmt::print("{:<24} {:>8} {:<16} {:>10.3f} {:>9} {:>10.2f} {:>10} {:>9.3f}\n", "total", "", "", log_span, "",
               static_cast<double>(total) / 1e6, "", perSecond(total));
    if (reader.corruptFrames() || reader.truncated()) {
      spdlog::error("log '{}' is damaged: {} corrupt frame(s) skipped{}", *path, reader.corruptFrames(),
                    reader.truncated() ? ", truncated at the end" : "");
      throw CLI::RuntimeError(kExitDamagedInput);
    }
  });
}
