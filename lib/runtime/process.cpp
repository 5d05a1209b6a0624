#include "runtime/process.hpp"

#include "runtime/allocator.hpp"
#include "runtime/resources.hpp"
#include "runtime/status.hpp"

#include <lcm/lcm-cpp.hpp>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <csignal>
#include <cstdlib>

namespace adit::runtime {
namespace {

volatile std::sig_atomic_t g_stop = 0;  // the one process-wide flag a signal handler may set

void onSignal(int) { g_stop = 1; }

// The node's latency probe, live: the kernel's receive time of each origin message (LCM's recv_utime, wall
// clock) against the wall time its output was published.
class LatencyProbe {
 public:
  LatencyProbe(std::string name, std::string origin, std::string output)
      : name_(std::move(name)), origin_(std::move(origin)), output_(std::move(output)) {}
  const std::string& origin() const { return origin_; }
  // Every adit message starts with its 8-byte fingerprint and then header.utime (big-endian int64).
  void onOrigin(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    if (rbuf->data_size < 16) return;
    const auto* b = static_cast<const std::uint8_t*>(rbuf->data) + 8;
    std::uint64_t utime = 0;
    for (int i = 0; i < 8; ++i) utime = (utime << 8) | b[i];
    tracker_.arrived(static_cast<std::int64_t>(utime), rbuf->recv_utime);
  }
  void onPublished(const std::string& channel, std::int64_t utime) {
    if (channel == output_) tracker_.completed(utime, wallUtime());
  }
  void report(adit::status_t& status) const { addLatencyCounters(status, name_, tracker_.summary()); }

 private:
  std::string name_, origin_, output_;
  LatencyTracker tracker_;
};

class LcmSink : public Sink {
 public:
  LcmSink(lcm::LCM& lcm, PublishedTraffic& traffic, LatencyProbe* probe)
      : lcm_(lcm), traffic_(traffic), probe_(probe) {}
  void publish(const std::string& channel, const Bytes& data, std::int64_t utime) override {
    lcm_.publish(channel, data.data(), static_cast<unsigned int>(data.size()));
    traffic_.add(channel, data.size());
    if (probe_) probe_->onPublished(channel, utime);
  }

 private:
  lcm::LCM& lcm_;
  PublishedTraffic& traffic_;
  LatencyProbe* probe_;
};

// Receives raw LCM buffers and hands them to the node.
class Receiver {
 public:
  Receiver(Node& node, Sink& sink) : node_(node), sink_(sink) {}
  void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    node_.deliver(channel, static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size, sink_);
  }

 private:
  Node& node_;
  Sink& sink_;
};

}  // namespace

bool stopRequested() { return g_stop != 0; }

void installStopHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

std::int64_t wallUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

void addProcessOptions(CLI::App& app, ProcessOptions& o) {
  app.add_option("--lcm-url", o.lcm_url, "LCM provider to subscribe to (default: $LCM_DEFAULT_URL or udpm)");
  app.add_option("--out-url", o.out_url, "LCM provider to publish to (default: the --lcm-url one)");
  app.add_option("--config", o.config_paths,
                 "YAML configuration, repeatable: later files override earlier ones (default: built-in defaults, "
                 "which launch/config/pipeline.yaml lists)");
  app.add_option("--set", o.config_sets, "Configuration key over the --config files: KEY=VALUE (repeatable), e.g. reloc.prior_map=DIR");
  app.add_option("--channel", o.channel_remaps, "Rename a channel: PORT=CHANNEL (repeatable)");
  app.add_option("--status-period", o.status_period_s, "Seconds between STATUS messages")->check(CLI::PositiveNumber);
  app.add_option("--run-dir", o.run_dir,
                 "Run folder for the files commands ask for and for checkpoints (default: $ADIT_RUN_DIR, else .)");
  app.add_option("--status-channel", o.status_channel, "STATUS channel (default STATUS_<process>)");
  app.add_option("--command-key", o.command_key,
                 "Obey only commands signed with this key file (`adit command keygen`; default: $ADIT_COMMAND_KEY, "
                 "else commands are not signed)");
}

std::string commandKeyPath(const std::string& flag_path) {
  if (!flag_path.empty()) return flag_path;
  const char* env = std::getenv("ADIT_COMMAND_KEY");
  return env ? std::string(env) : std::string();
}

Config loadConfig(const std::vector<std::string>& paths) {
  Config config;
  for (const auto& path : paths) {
    const Config file = Config::fromYamlFile(path);
    // An empty file is a mistake (a wrong path, a file cut to nothing), not "no changes".
    if (file.values().empty()) throw std::runtime_error("config: '" + path + "' holds no configuration key (empty file?)");
    config.merge(file);
  }
  return config;
}

void applyConfigSets(Config& config, const std::vector<std::string>& sets) {
  for (const auto& s : sets) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw std::runtime_error("--set expects KEY=VALUE, got '" + s + "'");
    config.set(s.substr(0, eq), s.substr(eq + 1));
  }
}

void applyRemaps(Node& node, const std::vector<std::string>& remaps) {
  for (const auto& r : remaps) {
    const auto eq = r.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == r.size())
      throw std::runtime_error("--channel expects PORT=CHANNEL, got '" + r + "'");
    node.remap(r.substr(0, eq), r.substr(eq + 1));
  }
}

int runNodeProcess(int argc, char** argv, const std::string& name, const std::string& description,
                   const NodeFactory& factory) {
  keepFreedMemoryForReuse(kLongRunHeapBlock);
  allocateFromOneHeap();
  CLI::App app{description, "adit-" + name};
  ProcessOptions options;
  addProcessOptions(app, options);
  CLI11_PARSE(app, argc, argv);
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ adit-" + name + ": %v");

  std::unique_ptr<Node> node;
  try {
    Config config = loadConfig(options.config_paths);
    applyConfigSets(config, options.config_sets);
    node = factory(config);
    applyRemaps(*node, options.channel_remaps);
    node->useRunFolder(liveRunFolder(options.run_dir));
    // An unreadable key stops the process: the operator asked for signed commands, so obeying anyone is wrong.
    const std::string key_path = commandKeyPath(options.command_key);
    if (!key_path.empty()) {
      node->requireSignedCommands(readCommandKey(key_path));
      spdlog::info("commands must be signed with the key in {}", key_path);
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }

  lcm::LCM in(options.lcm_url);
  if (!in.good()) {
    spdlog::error("cannot open LCM '{}' (for udpm on one machine: ip route add 224.0.0.0/4 dev lo)", options.lcm_url);
    return 1;
  }
  std::unique_ptr<lcm::LCM> separate_out;
  if (!options.out_url.empty()) {
    separate_out = std::make_unique<lcm::LCM>(options.out_url);
    if (!separate_out->good()) {
      spdlog::error("cannot open LCM '{}' for publishing", options.out_url);
      return 1;
    }
  }
  lcm::LCM& out = separate_out ? *separate_out : in;
  PublishedTraffic traffic;
  std::unique_ptr<LatencyProbe> probe;
  if (const Node::LatencyProbe p = node->latencyProbe(); !p.origin_channel.empty() && node->channels().count(p.output_port))
    probe = std::make_unique<LatencyProbe>(p.name, p.origin_channel, node->channels().at(p.output_port));
  LcmSink sink(out, traffic, probe.get());
  Receiver receiver(*node, sink);
  for (const auto& channel : node->inputChannels()) in.subscribe(channel, &Receiver::onMessage, &receiver);
  if (probe) in.subscribe(probe->origin(), &LatencyProbe::onOrigin, probe.get());

  installStopHandlers();
  const std::string status_channel = options.status_channel.empty() ? statusChannel(name) : options.status_channel;
  const auto start = std::chrono::steady_clock::now();
  auto last_status = start;
  auto last_trim = start;
  MemoryUse memory = returnFreeMemory();
  ProcessResources resources = readProcessResources();  // read right after the trim, as the memory
  constexpr std::chrono::seconds kReturnFreeMemoryPeriod{30};  // runtime/allocator.hpp
  std::int64_t status_seq = 0, inputs_at_last_status = 0;
  double busy_at_last_status = 0;
  // A stage busy this share of the time cannot keep up: its socket buffer fills and sweeps get lost.
  constexpr double kBehindBusyFraction = 0.9;
  const auto sendStatus = [&](const std::string& state) {
    const auto now = std::chrono::steady_clock::now();
    const double window = std::chrono::duration<double>(now - last_status).count();
    const Health& h = node->health();
    const double rate = window > 0 ? static_cast<double>(h.inputs - inputs_at_last_status) / window : 0.0;
    const double busy = window > 0 ? (h.busy_s - busy_at_last_status) / window : 0.0;
    const std::string reported = state == "running" && busy > kBehindBusyFraction ? "behind" : state;
    if (reported == "behind") spdlog::warn("busy {:.0f}% of the time: falling behind its input", busy * 100);
    adit::status_t status = makeStatus(*node, wallUtime(), status_seq++,
                                       std::chrono::duration<double>(now - start).count(), rate, busy, reported);
    addMemoryCounters(status, memory, resources);
    traffic.report(status, window);
    if (probe) probe->report(status);
    const Bytes bytes = msg::encode(status);
    out.publish(status_channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
    traffic.add(status_channel, bytes.size());
    last_status = now;
    inputs_at_last_status = h.inputs;
    busy_at_last_status = h.busy_s;
  };

  spdlog::info("listening on {} (status on {})", fmt::join(node->inputChannels(), ", "), status_channel);
  sendStatus("starting");
  bool end_of_input = false;
  while (!stopRequested()) {
    if (in.handleTimeout(100) < 0) {  // end of a file:// log, or a broken provider
      end_of_input = true;
      break;
    }
    if (std::chrono::steady_clock::now() - last_status >= std::chrono::duration<double>(options.status_period_s))
      sendStatus(node->state());
    if (std::chrono::steady_clock::now() - last_trim >= kReturnFreeMemoryPeriod) {
      memory = returnFreeMemory();
      resources = readProcessResources();
      last_trim = std::chrono::steady_clock::now();
    }
  }
  node->finish(sink);
  sendStatus("stopping");
  const Health& h = node->health();
  spdlog::info("{}: {} inputs, {} outputs, {} dropped, {} errors", end_of_input ? "end of input" : "stopped",
               h.inputs, h.outputs, h.drops, h.errors);
  return 0;
}

}  // namespace adit::runtime
