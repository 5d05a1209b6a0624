// The simulator's lidar on its own UDP link (`adit sim --lidar-udp`, sources/sim_lidar_udp.hpp): the packets
// it sends over the loopback, received and decoded as adit-lidar-bridge does (time source utc), give back the
// simulator's sweeps: the same end times (the ground truth's) and every return. A lost packet on that link
// costs its firings only, and is counted.
#include "drivers/lidar_stream.hpp"
#include "drivers/udp_receiver.hpp"
#include "runtime/process.hpp"
#include "sources/sim_lidar_udp.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <map>

namespace adit::sources {
namespace {

// The simulated sweep that ends at `utime`: the packets' stamps are whole microseconds, so the decoded end
// may lie a microsecond off the simulator's.
std::map<std::int64_t, std::size_t>::const_iterator sweepEndingAt(const std::map<std::int64_t, std::size_t>& sweeps,
                                                                   std::int64_t utime) {
  auto it = sweeps.lower_bound(utime - 1);
  return it != sweeps.end() && it->first <= utime + 1 ? it : sweeps.end();
}

struct LinkRun {
  std::map<std::int64_t, std::size_t> sim_returns;  // by sweep utime, as the simulator made them
  std::vector<LidarScan> sweeps;                     // decoded from the packets
  Trajectory truth;
  runtime::Health stream, source;
};

// One second of simulated roadway sent over 127.0.0.1; `drop(k)` says whether the k-th packet sent is lost.
LinkRun runLink(const std::function<bool(std::int64_t)>& drop) {
  sim::SimConfig config = sim::simConfigFrom(Config{}, "roadway-straight", 3);
  config.sensor = "vlp16";
  config.duration_s = 1.0;
  config.start_utime = runtime::wallUtime() / 1000 * 1000;  // the packets' stamps are UTC, as cmd_sim does
  SimChannels channels;
  channels.sweep_bytes = false;
  SimSource sim(config, channels);
  drivers::UdpReceiver receiver("127.0.0.1", 0, 8 * 1024 * 1024);
  LinkRun run;
  sim.addSweepObserver([&run](const LidarScan& scan) { run.sim_returns[scan.utime] = scan.points.size(); });
  SimLidarUdpSource link(sim, "127.0.0.1", receiver.port());

  drivers::LidarStreamConfig stream_config;
  stream_config.clock.source = drivers::TimeSource::kUtc;
  drivers::LidarPacketStream stream(stream_config);
  std::vector<std::uint8_t> payload;
  std::int64_t received = 0;
  runtime::OutgoingMessage m;
  while (link.next(m)) {
    if (!m.send) continue;
    EXPECT_TRUE(m.data.empty());  // nothing for LCM: the sweep leaves as packets
    m.send();
    std::size_t size = 0;
    std::int64_t receive_ns = 0;
    std::string error;
    while (receiver.receive(payload, size, receive_ns, 20, error) == drivers::UdpReceiver::Result::kPacket)
      if (!drop(received++)) stream.push(payload.data(), size, receive_ns, run.sweeps);
  }
  run.truth = sim.groundTruth();
  run.stream = stream.health();
  run.source = link.health();
  return run;
}

TEST(SimLidarLink, PacketsComeBackAsTheSimulatorsSweeps) {
  const LinkRun run = runLink([](std::int64_t) { return false; });
  EXPECT_EQ(run.source.counters.at("lidar_send_errors"), 0);
  // 10 sweeps; the first revolution seen began mid-way (dropped, as live) and the last is still open.
  ASSERT_EQ(run.truth.size(), 10u);
  ASSERT_EQ(run.sweeps.size(), 8u);
  EXPECT_EQ(run.stream.counters.count("lost_packets"), 0u);
  EXPECT_EQ(run.stream.counters.count("clock_not_utc"), 0u);
  for (const LidarScan& s : run.sweeps) {
    const auto made = sweepEndingAt(run.sim_returns, s.utime);
    ASSERT_NE(made, run.sim_returns.end()) << "no simulated sweep ends at " << s.utime;
    EXPECT_EQ(s.points.size(), made->second);
  }
  EXPECT_LE(std::llabs(run.sweeps.front().utime - run.truth[1].utime), 1);
}

TEST(SimLidarLink, ALostPacketCostsItsFiringsAndIsCounted) {
  const LinkRun run = runLink([](std::int64_t k) { return k == 300 || k == 450; });
  ASSERT_EQ(run.sweeps.size(), 8u);  // holes of one packet keep their sweeps
  EXPECT_EQ(run.stream.counters.at("lost_packets"), 2);
  std::size_t short_sweeps = 0, missing = 0;
  for (const LidarScan& s : run.sweeps) {
    const auto it = sweepEndingAt(run.sim_returns, s.utime);
    ASSERT_NE(it, run.sim_returns.end()) << "no simulated sweep ends at " << s.utime;
    const std::size_t made = it->second;
    ASSERT_LE(s.points.size(), made);
    if (s.points.size() < made) ++short_sweeps;
    missing += made - s.points.size();
  }
  EXPECT_EQ(short_sweeps, 2u);
  EXPECT_GT(missing, 0u);
  EXPECT_LE(missing, 2u * 384);  // a packet holds 24 x 16 firings
}

}  // namespace
}  // namespace adit::sources
