// A simulated VLP-16 run written as the packet capture a real sensor would give (`adit sim --pcap`), read back
// by the pcap source (`adit import pcap` / adit-lidar-bridge --source pcap) and run through the whole pipeline
// with the run's IMU: the same accuracy as the simulator's own log (APE within 5 %).
#include "eval/evaluate.hpp"
#include "eval/trajectory_io.hpp"
#include "pipeline/replay.hpp"
#include "runtime/process.hpp"
#include "sources/pcap_source.hpp"
#include "sources/sim_pcap.hpp"
#include "sources/sim_source.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

namespace adit {
namespace {

namespace fs = std::filesystem;

class VectorSource : public runtime::MessageSource {
 public:
  explicit VectorSource(std::vector<runtime::OutgoingMessage> messages) : messages_(std::move(messages)) {}
  bool next(runtime::OutgoingMessage& m) override {
    if (index_ >= messages_.size()) return false;
    m = messages_[index_++];
    return true;
  }
  const runtime::Health& health() const override { return health_; }

 private:
  std::vector<runtime::OutgoingMessage> messages_;
  std::size_t index_ = 0;
  runtime::Health health_;
};

Config pipelineConfig() {
  const fs::path launch = fs::path(ADIT_SOURCE_DIR) / "launch";
  return runtime::loadConfig({(launch / "config" / "pipeline.yaml").string(), (launch / "sensors" / "sim.yaml").string()});
}

struct ReplayRun {
  double ape_rmse_m = 0;
  std::int64_t sweeps = 0;
};

ReplayRun replay(std::vector<runtime::OutgoingMessage> messages, const Trajectory& truth, const std::string& tag) {
  VectorSource source(std::move(messages));
  pipeline::ReplayOptions options;
  options.source = &source;
  options.out_dir = (fs::temp_directory_path() / ("adit_pcap_replay_" + tag + "_" + std::to_string(::getpid()))).string();
  options.config = pipelineConfig();
  options.record = "";
  const pipeline::ReplayReport report = pipeline::runReplay(options);
  ReplayRun run;
  run.sweeps = report.sweeps;
  const eval::EvalResult r = eval::evaluate(truth, eval::readTum(options.out_dir + "/trajectory.tum"));
  EXPECT_TRUE(r.valid) << r.message;
  run.ape_rmse_m = r.ape_m.rmse;
  fs::remove_all(options.out_dir);
  return run;
}

TEST(PcapReplay, SameAccuracyAsTheSimulatorsLog) {
  sim::SimConfig sim = sim::simConfigFrom(pipelineConfig());
  sim.world = "roadway-loop";
  sim.sensor = "vlp16";
  sim.duration_s = 20.0;
  sim.seed = 4;
  sources::SimSource source(sim, sources::SimChannels{});
  const std::string pcap = (fs::temp_directory_path() / ("adit_pcap_replay_" + std::to_string(::getpid()) + ".pcap")).string();
  std::vector<runtime::OutgoingMessage> logged;
  std::int64_t packets = 0;
  {
    std::ofstream out(pcap, std::ios::binary);
    sources::SimPcapRecorder recorder(source.simulator().lidar(), out);
    source.setSweepObserver([&recorder](const LidarScan& scan) { recorder.addSweep(scan); });
    runtime::OutgoingMessage m;
    while (source.next(m)) logged.push_back(m);
    packets = recorder.packets();
  }
  // The capture's sweeps in place of the log's, with the log's IMU (and ground truth) around them.
  std::vector<runtime::OutgoingMessage> from_pcap;
  drivers::UdpLidarConfig lidar;
  lidar.model = "vlp16";
  auto capture = sources::makePcapLidarSource(pcap, lidar);
  runtime::OutgoingMessage m;
  while (capture->next(m)) from_pcap.push_back(m);
  const runtime::Health health = capture->health();
  fs::remove(pcap);
  for (const auto& message : logged)
    if (message.channel != "LIDAR_POINTS") from_pcap.push_back(message);
  std::stable_sort(from_pcap.begin(), from_pcap.end(),
                   [](const auto& a, const auto& b) { return a.utime < b.utime; });

  // The capture's first revolution begins at the first packet, which the driver cannot know is a cut: it is
  // dropped as live. Both runs start at the same sweep, so that what is compared is the capture, not a start.
  const auto first_sweep = std::find_if(logged.begin(), logged.end(),
                                        [](const runtime::OutgoingMessage& m) { return m.channel == "LIDAR_POINTS"; });
  if (first_sweep != logged.end()) logged.erase(first_sweep);
  const ReplayRun log_run = replay(logged, source.groundTruth(), "log");
  const ReplayRun pcap_run = replay(from_pcap, source.groundTruth(), "pcap");
  std::printf("%lld packets; sweeps: log %lld, pcap %lld; APE rmse: log %.4f m, pcap %.4f m (%+.1f %%)\n",
              static_cast<long long>(packets), static_cast<long long>(log_run.sweeps),
              static_cast<long long>(pcap_run.sweeps), log_run.ape_rmse_m, pcap_run.ape_rmse_m,
              100.0 * (pcap_run.ape_rmse_m / log_run.ape_rmse_m - 1.0));
  EXPECT_EQ(health.errors, 0);
  // Every revolution after the first is there, the last flagged partial.
  EXPECT_EQ(pcap_run.sweeps, log_run.sweeps);
  // The capture's 2 mm range steps and per-firing times give the pipeline slightly different points: the
  // APE stays within 5 % of the log's either way (measured -4.9 %).
  EXPECT_LE(std::abs(pcap_run.ape_rmse_m - log_run.ape_rmse_m), 0.05 * log_run.ape_rmse_m);
}

}  // namespace
}  // namespace adit
