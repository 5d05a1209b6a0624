// adit export mcap <log> [<log> ...] -o run.mcap: a run as MCAP with Foxglove schemas (foxglove/foxglove_run.hpp),
// for Foxglove and Lichtblick. Several logs (the sensor log and a replay's output.lcmlog) merge by time.
#include "commands.hpp"

#include "foxglove/mcap_sink.hpp"
#include "io/atomic_file.hpp"
#include "view/merged_logs.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>


namespace {

struct ExportArgs {
  std::vector<std::string> logs;
  std::string out;
  std::string compression = "zstd";
  std::size_t chunk_mb = 4;
  adit::foxglove::ExportOptions options;
};

void runExport(const ExportArgs& args) {
  adit::io::McapOptions mcap;
  mcap.compression = args.compression == "none" ? adit::io::McapCompression::None : adit::io::McapCompression::Zstd;
  mcap.chunk_bytes = args.chunk_mb << 20;
  adit::view::MergedLogs logs(args.logs);
  if (logs.empty())
    throw std::runtime_error(fmt::format("'{}' hold(s) no LCM event (empty, or not an LCM log): nothing exported",
                                         fmt::join(args.logs, "', '")));
  std::uint64_t events = 0;
  std::map<std::string, std::uint64_t> topics;
  adit::view::DecodeCounts counts;
  adit::io::writeFileAtomically(args.out, [&](std::ostream& out) {
    adit::io::McapWriter writer(out, mcap);
    adit::foxglove::McapSink sink(writer);
    adit::foxglove::FoxgloveRun exporter(sink, args.options);
    adit::runtime::LogEvent e;
    while (logs.next(e)) {
      ++events;
      exporter.add(e.channel, e.data.data(), e.data.size(), e.timestamp);
    }
    exporter.finish();
    writer.finish();
    topics = exporter.topics();
    counts = exporter.decodeCounts();
  });
  fmt::print("{} events read, {} used; wrote {}\n", events, counts.used, args.out);
  for (const auto& [topic, n] : topics) fmt::print("  {:<26} {:>8} messages\n", topic, n);
  for (const auto& [channel, n] : counts.ignored) fmt::print("  not exported: {:<16} {:>8} messages\n", channel, n);
  if (counts.malformed || counts.out_of_order)
    spdlog::warn("{} malformed message(s) and {} pose(s) out of order skipped (last: {})", counts.malformed,
                 counts.out_of_order, counts.last_error);
  const auto damage = logs.damage();
  for (const auto& line : damage) spdlog::error("{}", line);
  if (!damage.empty()) throw CLI::RuntimeError(kExitDamagedInput);
}

}  // namespace

void registerExportCommand(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  auto* exp = app.add_subcommand("export", "Write a run in another format (mcap: for Foxglove / Lichtblick)");
  exp->require_subcommand(1);
  auto* cmd = exp->add_subcommand("mcap", "LCM log(s) of a run to MCAP with Foxglove schemas (JSON messages)");
  cmd->add_option("logs", args->logs, "LCM logs, merged by time (e.g. the sensor log and a replay's output.lcmlog)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--out", args->out, "MCAP file to write")->required();
  cmd->add_option("--compression", args->compression, "Chunk compression")
      ->check(CLI::IsMember({"zstd", "none"}))
      ->capture_default_str();
  cmd->add_option("--chunk-mb", args->chunk_mb, "Uncompressed MB per chunk")->check(CLI::Range(1, 1024))->capture_default_str();
  cmd->add_option("--sweep-every", args->options.sweep_every, "Export every n-th sweep of LIDAR_POINTS")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--map-period", args->options.map_period_s, "Least seconds between two /map clouds (a loop aside)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  cmd->add_option("--trajectory-period", args->options.trajectory_period_s,
                  "Least seconds between two trajectory messages")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  cmd->callback([args] { runExport(*args); });
}
