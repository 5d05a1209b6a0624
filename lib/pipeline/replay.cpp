#include "pipeline/replay.hpp"

#include "io/atomic_file.hpp"
#include "map/map_bundle.hpp"
#include "msg/convert.hpp"
#include "msg/encode.hpp"
#include "msg/type_name.hpp"
#include "nodes/products.hpp"
#include "nodes/registry.hpp"
#include "runtime/allocator.hpp"
#include "runtime/lcm_log.hpp"
#include "runtime/pipelined_bus.hpp"
#include "runtime/process.hpp"
#include "runtime/source.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <regex>
#include <stdexcept>

namespace adit::pipeline {
namespace fs = std::filesystem;

double peakMemoryMb() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmHWM:") {
      double kb = 0;
      status >> kb;
      return kb / 1024.0;
    }
    status.ignore(1 << 16, '\n');
  }
  return 0.0;
}

double processCpuSeconds() {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0.0;
  const auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6; };
  return seconds(u.ru_utime) + seconds(u.ru_stime);
}

namespace {

std::string timingJson(const ReplayReport& r) {
  std::string out = "{\n  \"stages\": {";
  for (std::size_t i = 0; i < r.timing.size(); ++i) {
    const StageTiming& t = r.timing[i];
    out += fmt::format("{}\n    \"{}\": {{\"calls\": {}, \"median_ms\": {:.3f}, \"p95_ms\": {:.3f}, \"max_ms\": {:.3f}, "
                       "\"cpu_median_ms\": {:.3f}, \"cpu_p95_ms\": {:.3f}, \"wall_total_ms\": {:.1f}, \"cpu_total_ms\": {:.1f}}}",
                       i ? "," : "", t.stage, t.calls, t.median_ms, t.p95_ms, t.max_ms, t.cpu_median_ms, t.cpu_p95_ms,
                       t.wall_total_ms, t.cpu_total_ms);
    if (t.counters.empty()) continue;
    out.pop_back();  // the stage's closing brace: its counters go inside
    out += ", \"counters\": {";
    for (auto it = t.counters.begin(); it != t.counters.end(); ++it)
      out += fmt::format("{}\"{}\": {}", it == t.counters.begin() ? "" : ", ", it->first, it->second);
    out += "}}";
  }
  out += fmt::format(
      "\n  }},\n  \"sweeps\": {},\n  \"sensor_seconds\": {:.3f},\n  \"wall_seconds\": {:.3f},\n"
      "  \"realtime_factor\": {:.2f},\n  \"peak_memory_mb\": {:.1f},\n  \"process_cpu_seconds\": {:.3f}\n}}\n",
      r.sweeps, r.sensor_seconds, r.wall_seconds, r.wall_seconds > 0 ? r.sensor_seconds / r.wall_seconds : 0.0,
      r.peak_memory_mb, r.process_cpu_seconds);
  return out;
}

// Every requested stage, in pipeline order.
std::vector<std::unique_ptr<runtime::Node>> buildNodes(const ReplayOptions& options, ReplayReport& report) {
  // Every stage is told the bundle: the relocaliser relocalises in it, a loop closer extending it joins it.
  Config config = options.config;
  if (!options.prior_map.empty()) config.set("reloc.prior_map", options.prior_map);
  std::vector<std::unique_ptr<runtime::Node>> nodes;
  const auto add = [&](const std::string& name) {
    nodes.push_back(nodes::makeNode(name, config));
    nodes.back()->timing().setCapacity(0);  // keep every sample for timing.json
    nodes.back()->cpuTiming().setCapacity(0);
    report.stages_run.push_back(name);
  };
  for (const auto& name : nodes::pipelineNodeNames())
    if (options.stages.empty() || std::find(options.stages.begin(), options.stages.end(), name) != options.stages.end())
      add(name);
  if (!options.prior_map.empty()) add("relocaliser");
  // Only the last map writer's map.pcd is kept (writeProducts below): the others need not build one.
  bool map_written_later = false;
  for (auto it = nodes.rbegin(); it != nodes.rend(); ++it) {
    auto* writer = dynamic_cast<nodes::WritesProducts*>(it->get());
    if (!writer) continue;
    if (map_written_later) writer->mapWrittenLater();
    map_written_later = map_written_later || writer->writesMap();
  }
  return nodes;
}

// The input of a replay: a log file or a message source, one event at a time.
class Input {
 public:
  explicit Input(const ReplayOptions& options) : source_(options.source) {
    if (!source_) log_ = std::make_unique<runtime::LogReader>(options.input_log);
  }
  bool next(runtime::LogEvent& event) {
    if (log_) return log_->next(event);
    runtime::OutgoingMessage message;
    if (!source_->next(message)) return false;
    event.channel = std::move(message.channel);
    event.data = std::move(message.data);
    event.timestamp = message.utime;
    return true;
  }
  double progress() const { return log_ ? log_->progress() : source_->progress(); }
  std::int64_t corruptFrames() const { return log_ ? log_->corruptFrames() : 0; }
  bool truncated() const { return log_ && log_->truncated(); }

 private:
  runtime::MessageSource* source_;
  std::unique_ptr<runtime::LogReader> log_;
};

// Products in pipeline order: a later stage's file replaces an earlier one's (see nodes/products.hpp).
void writeProducts(const std::vector<std::unique_ptr<runtime::Node>>& nodes, const std::string& out_dir,
                   std::vector<std::string>& products) {
  for (const auto& node : nodes) {
    auto* writer = dynamic_cast<nodes::WritesProducts*>(node.get());
    if (!writer || node->health().inputs == 0) continue;
    for (const auto& path : writer->writeProducts(out_dir))
      if (std::find(products.begin(), products.end(), path) == products.end()) products.push_back(path);
  }
}

// The map bundle from the last node that owns one (the loop closer).
void writeBundle(const std::vector<std::unique_ptr<runtime::Node>>& nodes, const std::string& dir,
                 std::vector<std::string>& products) {
  for (auto it = nodes.rbegin(); it != nodes.rend(); ++it) {
    if (auto* writer = dynamic_cast<nodes::WritesBundle*>(it->get())) {
      writeMapBundle(writer->mapBundle(), dir);
      products.push_back(dir);
      return;
    }
  }
  throw std::runtime_error("--save-bundle needs the loop_closer stage (it owns the map)");
}

}  // namespace

ReplayReport runReplay(const ReplayOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  ReplayReport report;
  fs::create_directories(options.out_dir);
  const auto nodes = buildNodes(options, report);
  Input input(options);
  runtime::LogWriter output((fs::path(options.out_dir) / "output.lcmlog").string());
  runtime::PipelinedBus bus(options.pipelined);
  const std::regex record(options.record), record_poses(options.record_poses);
  // A failed write (disk full) happens inside a node's publish, where stage errors are counted and the run
  // goes on: keep it here and end the replay with it after the delivery (the writer has removed its file).
  // The observer runs on the bus's worker thread when pipelined.
  std::mutex write_error_mutex;
  std::string write_error;
  bus.observe([&](const std::string& channel, const runtime::Bytes& data, std::int64_t utime) {
    std::lock_guard<std::mutex> lock(write_error_mutex);
    if (!write_error.empty()) return;
    try {
      if (std::regex_match(channel, record)) {
        output.write(channel, data, utime);
      } else if (!options.record_poses.empty() && std::regex_match(channel, record_poses)) {
        adit::odometry_t m;
        if (m.decode(data.data(), 0, static_cast<int>(data.size())) < 0) return;
        msg::stripPoints(m);
        output.write(channel, msg::encode(m), utime);
      }
    } catch (const std::exception& e) {
      write_error = e.what();
    }
  });
  const auto stopOnWriteError = [&] {
    std::lock_guard<std::mutex> lock(write_error_mutex);
    if (!write_error.empty()) throw std::runtime_error(write_error);
  };
  for (const auto& node : nodes) bus.add(*node);

  runtime::LogEvent event;
  std::int64_t first_utime = -1, last_utime = -1;
  while (!runtime::stopRequested() && input.next(event)) {
    ++report.input_events;
    const std::string type = msg::messageTypeName(event.data.data(), event.data.size());
    if (type == "lidar_scan_t" || type == "point_cloud_t") ++report.sweeps;
    if (first_utime < 0) first_utime = event.timestamp;
    last_utime = std::max(last_utime, event.timestamp);
    bus.inject(event.channel, event.data, event.timestamp);
    stopOnWriteError();
    if (options.on_progress && report.input_events % 64 == 0 && input.progress() >= 0) options.on_progress(input.progress());
  }
  if (report.input_events == 0 && !options.source)
    throw std::runtime_error("'" + options.input_log + "' holds no LCM event (empty, or not an LCM log): nothing replayed");
  bus.finish();
  stopOnWriteError();
  output.close();
  // The sweeps' freed buffers, kept for reuse while sweeps came (runtime/allocator.hpp), in every thread's
  // arena: handed back before the products are built, whose map is the run's memory peak.
  runtime::returnFreeMemory();
  if (options.on_progress) options.on_progress(1.0);

  report.corrupt_frames = input.corruptFrames();
  report.truncated = input.truncated();
  report.output_events = output.events();
  report.products.push_back(output.path());
  for (const auto& node : nodes) {
    const auto& t = node->timing();
    const auto& cpu = node->cpuTiming();
    report.timing.push_back({node->name(), t.size(), t.quantile(0.5), t.quantile(0.95), t.max(), cpu.quantile(0.5),
                             cpu.quantile(0.95), node->wallMsTotal(), node->cpuMsTotal(), node->health().counters});
    report.stage_errors += node->health().errors + node->health().drops;
  }
  report.sensor_seconds = first_utime >= 0 ? static_cast<double>(last_utime - first_utime) * 1e-6 : 0.0;
  report.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  report.process_cpu_seconds = processCpuSeconds();
  writeProducts(nodes, options.out_dir, report.products);
  if (!options.save_bundle.empty()) writeBundle(nodes, options.save_bundle, report.products);
  report.peak_memory_mb = peakMemoryMb();  // after the products: building the map is part of the run
  const fs::path timing_path = fs::path(options.out_dir) / "timing.json";
  io::writeFileAtomically(timing_path.string(), timingJson(report));
  report.products.push_back(timing_path.string());
  return report;
}

}  // namespace adit::pipeline
