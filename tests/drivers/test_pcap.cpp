// Recorded captures -> sweeps (CaptureLidarReader: capture reader, UDP extraction, the live driver's
// LidarPacketStream): a pcap written from the synthetic lidar's known firings, with a lost packet, a reordered
// pair (put back in order), a fragmented datagram and foreign traffic, decodes to those firings (position within 1 mm, ring exact,
// time to the sensor stamp's microsecond); the last revolution comes out flagged partial.
#include "io/capture_writer.hpp"
#include "msg/sweep_codec.hpp"
#include "runtime/source.hpp"
#include "sources/capture_lidar_reader.hpp"
#include "sources/pcap_source.hpp"
#include "synthetic_lidar.hpp"

#include <adit/lidar_scan_t.hpp>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>

namespace adit::sources {
namespace {

using drivers::testing::Model;
using drivers::testing::SyntheticLidar;
using drivers::testing::TruthFiring;

constexpr std::int64_t kHost0Ns = 1700000000LL * 1000000000;  // capture clock at packet 0's first firing
constexpr std::int64_t kLatencyNs = 100000;                    // last firing -> capture
constexpr std::uint32_t kSensorIp = 0xC0A801C9, kHostIp = 0xC0A80164, kOtherIp = 0xC0A80105;

struct Recording {
  int packets = 0;
  int lost = -1;        // never written
  int reordered = -1;   // written after packet reordered + 1 (put back in order by the reorder window)
  int late = -1;        // written kReorderWindow + 2 packets late: beyond the window, skipped
  int fragmented = -1;  // split into IP fragments of at most 576 bytes
  bool nanoseconds = false;
  std::vector<std::uint8_t> difop;  // RS-16: a DIFOP packet captured before the data (port 7788)
  std::function<void(std::vector<std::uint8_t>&)> mutate;  // rewrites every data packet
};

std::int64_t captureNs(const SyntheticLidar& lidar, int k) {
  return kHost0Ns + k * lidar.packetNs() + lidar.lastFiringNs() + kLatencyNs;
}

std::uint16_t portOf(const SyntheticLidar& lidar) { return lidar.model == Model::kVlp16 ? 2368 : 6699; }

io::UdpDatagram datagram(std::int64_t time_ns, std::uint32_t src, std::uint16_t port, std::vector<std::uint8_t> payload) {
  io::UdpDatagram d;
  d.time_ns = time_ns;
  d.src_ip = src;
  d.dst_ip = kHostIp;
  d.src_port = port;
  d.dst_port = port;
  d.payload = std::move(payload);
  return d;
}

// The capture as tcpdump on the host would have written it, with foreign traffic mixed in: an ARP frame, a
// VLP-16 position packet (port 8308) and a datagram from another host to the data port.
std::string writeRecording(const SyntheticLidar& lidar, const Recording& r) {
  std::ostringstream out;
  io::PcapWriter pcap(out, r.nanoseconds);
  std::vector<int> order;
  for (int k = 0; k < r.packets; ++k)
    if (k != r.lost) order.push_back(k);
  if (r.reordered >= 0) {
    const auto at = std::find(order.begin(), order.end(), r.reordered);
    std::iter_swap(at, at + 1);
  }
  if (r.late >= 0) {
    order.erase(std::find(order.begin(), order.end(), r.late));
    order.insert(std::find(order.begin(), order.end(), r.late + static_cast<int>(kReorderWindow) + 2) + 1, r.late);
  }
  if (!r.difop.empty()) pcap.writeUdp(datagram(captureNs(lidar, 0) - 1000000, kSensorIp, 7788, r.difop));
  for (int k : order) {
    const std::int64_t t = captureNs(lidar, k);
    std::vector<std::uint8_t> packet = lidar.packet(k);
    if (r.mutate) r.mutate(packet);
    pcap.writeUdp(datagram(t, kSensorIp, portOf(lidar), packet), k == r.fragmented ? 576 : 1500);
    if (k == 3) {
      std::vector<std::uint8_t> arp(42, 0);
      arp[12] = 0x08;
      arp[13] = 0x06;
      pcap.writeFrame(t + 10, arp);
      pcap.writeUdp(datagram(t + 20, kSensorIp, 8308, std::vector<std::uint8_t>(512, 7)));
      pcap.writeUdp(datagram(t + 30, kOtherIp, portOf(lidar), packet));
    }
  }
  return out.str();
}

drivers::UdpLidarConfig configOf(const SyntheticLidar& lidar) {
  drivers::UdpLidarConfig c;
  c.model = lidar.model == Model::kVlp16 ? "vlp16" : "rs16";
  return c;
}

struct Decoded {
  std::vector<LidarScan> sweeps;
  runtime::Health health;
};

Decoded decode(const std::string& bytes, const drivers::UdpLidarConfig& config) {
  std::istringstream in(bytes);
  CaptureLidarReader reader(in, "test.pcap", config);
  Decoded d;
  while (reader.read(d.sweeps)) {
  }
  d.health = reader.health();
  return d;
}

// Every point of every sweep is a distinct truth return of a packet that was captured, at its time (to the
// microsecond of the sensor stamps) and position (1 mm), with its ring; and every such return after the first
// pass of the cut angle is there.
void expectPointsMatchTruth(const SyntheticLidar& lidar, const Recording& r, const Decoded& d) {
  struct Truth {
    TruthFiring f;
    bool used = false;
  };
  std::vector<std::vector<Truth>> by_ring(16);
  std::size_t expected = 0;
  for (int k = 0; k < r.packets; ++k) {
    if (k == r.lost || k == r.late) continue;
    std::vector<TruthFiring> truth;
    lidar.packet(k, &truth);
    for (const TruthFiring& f : truth) {
      if (!f.has_return) continue;
      const double unwrapped = (lidar.az0_centideg + lidar.gap_centideg * static_cast<double>(f.t_ns) /
                                                         static_cast<double>(lidar.blockNs())) / 100.0;
      if (std::floor((unwrapped - 180.0) / 360.0) > std::floor((lidar.az0_centideg / 100.0 - 180.0) / 360.0)) ++expected;
      by_ring[static_cast<std::size_t>(f.ring)].push_back({f});
    }
  }
  const std::int64_t anchor = kHost0Ns + kLatencyNs;
  std::size_t matched = 0;
  for (const LidarScan& s : d.sweeps) {
    for (const LidarPoint& p : s.points) {
      ASSERT_LT(p.ring, 16);
      const double t = static_cast<double>(s.utime * 1000 - anchor) + static_cast<double>(p.dt) * 1e9;
      auto& candidates = by_ring[p.ring];
      auto best = candidates.end();
      for (auto it = candidates.begin(); it != candidates.end(); ++it)
        if (!it->used && std::abs(static_cast<double>(it->f.t_ns) - t) < 2500.0 &&
            (it->f.p - p.p.cast<double>()).norm() < 1e-3)
          best = it;
      ASSERT_NE(best, candidates.end()) << "no truth firing of ring " << p.ring << " at " << t << " ns, " << p.p.transpose();
      best->used = true;
      EXPECT_EQ(p.intensity, best->f.intensity);
      ++matched;
    }
  }
  EXPECT_EQ(matched, expected);
}

struct Case {
  const char* name;
  Model model;
  bool dual;
};

class PcapRecording : public ::testing::TestWithParam<Case> {};

TEST_P(PcapRecording, DecodesToTheKnownFiringsDespiteLossReorderAndFragments) {
  SyntheticLidar lidar;
  lidar.model = GetParam().model;
  lidar.dual = GetParam().dual;
  lidar.stamp0_us = lidar.model == Model::kVlp16 ? 777777 : drivers::testing::kRs16TestEpochUs + 5;
  Recording r;
  r.packets = static_cast<int>(3.6 * lidar.rotationNs() / static_cast<double>(lidar.packetNs()));
  r.lost = 40;
  r.reordered = 100;
  r.fragmented = 150;
  // An RS-16 says its return mode only in DIFOP packets: the recording holds one (nominal angles).
  if (lidar.model == Model::kRs16) r.difop = drivers::testing::rs16DifopPacket(lidar.dual, drivers::testing::nominalRs16Elevations());
  const Decoded d = decode(writeRecording(lidar, r), configOf(lidar));
  // The first revolution began mid-way (dropped), three complete ones, the last one partial.
  ASSERT_EQ(d.sweeps.size(), 4u);
  for (std::size_t j = 0; j < 3; ++j) EXPECT_FALSE(d.sweeps[j].partial);
  EXPECT_TRUE(d.sweeps[3].partial);
  expectPointsMatchTruth(lidar, r, d);
  EXPECT_EQ(d.health.inputs, r.packets - 1);  // the lost one
  EXPECT_EQ(d.health.counters.at("reordered"), 1);  // put back in place: nothing skipped
  EXPECT_EQ(d.health.counters.count("time_backwards"), 0u);
  EXPECT_EQ(d.health.counters.at("other_port"), 1);
  EXPECT_EQ(d.health.counters.at("other_host"), 1);
  EXPECT_EQ(d.health.counters.at("not_ipv4"), 1);
  EXPECT_EQ(d.health.counters.at("partial_sweep_published"), 1);
  EXPECT_EQ(d.health.errors, 0);
}

INSTANTIATE_TEST_SUITE_P(Sensors, PcapRecording,
                         ::testing::Values(Case{"vlp16", Model::kVlp16, false}, Case{"vlp16_dual", Model::kVlp16, true},
                                           Case{"rs16", Model::kRs16, false}, Case{"rs16_dual", Model::kRs16, true}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(PcapRecording, Rs16DifopCalibratedAnglesReplaceTheNominalOnes) {
  SyntheticLidar lidar;
  lidar.model = Model::kRs16;
  lidar.stamp0_us = drivers::testing::kRs16TestEpochUs;
  Recording r;
  r.packets = 200;
  std::array<double, 16> calibrated = drivers::testing::nominalRs16Elevations();
  for (std::size_t i = 0; i < 16; ++i) calibrated[i] += (i < 8 ? -0.137 : 0.211);
  r.difop = drivers::testing::rs16DifopPacket(false, calibrated);
  const Decoded d = decode(writeRecording(lidar, r), configOf(lidar));
  EXPECT_EQ(d.health.counters.at("difop"), 1);
  EXPECT_EQ(d.health.counters.at("difop_applied"), 1);
  ASSERT_GE(d.sweeps.size(), 2u);
  std::size_t checked = 0;
  for (const LidarPoint& p : d.sweeps[1].points) {
    // Ring r is laser r (RS-16 rings 0..7 = lasers 0..7, 8..15 = lasers 15..8).
    const std::size_t laser = p.ring < 8 ? p.ring : 23u - p.ring;
    EXPECT_NEAR(std::asin(p.p.z() / p.p.norm()) * 180.0 / M_PI, calibrated[laser], 2e-3);
    ++checked;
  }
  EXPECT_GT(checked, 10000u);
  // A configured table is the user's calibration: it wins over the sensor's.
  drivers::UdpLidarConfig config = configOf(lidar);
  const std::array<double, 16> nominal = drivers::testing::nominalRs16Elevations();
  config.vertical_angles_deg.assign(nominal.begin(), nominal.end());
  const Decoded mine = decode(writeRecording(lidar, r), config);
  EXPECT_EQ(mine.health.counters.count("difop_applied"), 0u);
  expectPointsMatchTruth(lidar, r, mine);
}

TEST(PcapRecording, Vlp16AnnouncingAnotherProductNeedsTheConfigKey) {
  SyntheticLidar lidar;
  Recording r;
  r.packets = 200;
  r.mutate = [](std::vector<std::uint8_t>& p) { p[1205] = 0x24; };
  const Decoded refused = decode(writeRecording(lidar, r), configOf(lidar));
  EXPECT_TRUE(refused.sweeps.empty());
  EXPECT_EQ(refused.health.counters.at("unknown_product"), r.packets);
  EXPECT_EQ(refused.health.counters.at("other_host"), 1);
  drivers::UdpLidarConfig config = configOf(lidar);
  config.accept_product_ids = {0x24};
  const Decoded accepted = decode(writeRecording(lidar, r), config);
  EXPECT_EQ(accepted.health.counters.count("unknown_product"), 0u);
  expectPointsMatchTruth(lidar, r, accepted);
}

TEST(PcapRecording, APacketLaterThanTheReorderWindowIsSkipped) {
  SyntheticLidar lidar;
  Recording r;
  r.packets = 200;
  r.late = 60;
  const Decoded d = decode(writeRecording(lidar, r), configOf(lidar));
  EXPECT_EQ(d.health.counters.at("time_backwards"), 1);
  ASSERT_GE(d.sweeps.size(), 2u);
  expectPointsMatchTruth(lidar, r, d);
}

TEST(PcapRecording, NanosecondFileGivesTheSameSweeps) {
  SyntheticLidar lidar;
  Recording r;
  r.packets = 200;
  const Decoded micro = decode(writeRecording(lidar, r), configOf(lidar));
  r.nanoseconds = true;
  const Decoded nano = decode(writeRecording(lidar, r), configOf(lidar));
  ASSERT_EQ(micro.sweeps.size(), nano.sweeps.size());
  ASSERT_GE(micro.sweeps.size(), 2u);
  for (std::size_t j = 0; j < micro.sweeps.size(); ++j) EXPECT_EQ(micro.sweeps[j].points.size(), nano.sweeps[j].points.size());
}

TEST(PcapRecording, HostTimeUsesTheCaptureTimes) {
  SyntheticLidar lidar;
  Recording r;
  r.packets = 200;
  drivers::UdpLidarConfig config = configOf(lidar);
  config.time_source = "host";
  const Decoded d = decode(writeRecording(lidar, r), config);
  ASSERT_GE(d.sweeps.size(), 2u);
  expectPointsMatchTruth(lidar, r, d);
}

TEST(PcapRecording, Rs16WithoutAClockFallsBackToCaptureTimes) {
  SyntheticLidar lidar;
  lidar.model = Model::kRs16;
  lidar.stamp0_us = drivers::testing::kRs16TestEpochUs;
  Recording r;
  r.packets = 200;
  // Every header date zeroed (year 2000, month 0: a clock never set).
  std::ostringstream out;
  io::PcapWriter pcap(out);
  for (int k = 0; k < r.packets; ++k) {
    std::vector<std::uint8_t> p = lidar.packet(k);
    std::fill(p.begin() + 20, p.begin() + 30, 0);
    pcap.writeUdp(datagram(captureNs(lidar, k), kSensorIp, 6699, p));
  }
  const Decoded d = decode(out.str(), configOf(lidar));
  EXPECT_EQ(d.health.counters.at("host_time_fallback"), 1);
  EXPECT_EQ(d.health.counters.count("bad_timestamp"), 0u);
  ASSERT_GE(d.sweeps.size(), 2u);
  expectPointsMatchTruth(lidar, r, d);
}

TEST(PcapRecording, SensorAddressKeyPicksTheSensor) {
  SyntheticLidar lidar;
  Recording r;
  r.packets = 100;
  drivers::UdpLidarConfig config = configOf(lidar);
  config.sensor_address = "192.168.1.5";  // the other host: only its one packet counts
  const Decoded d = decode(writeRecording(lidar, r), config);
  EXPECT_EQ(d.health.inputs, 1);
  EXPECT_EQ(d.health.counters.at("other_host"), r.packets);
  config.sensor_address = "not an address";
  EXPECT_THROW(decode(writeRecording(lidar, r), config), std::invalid_argument);
}

// The message source the bridge and `adit import pcap` run: compact sweeps, the last one flagged partial.
TEST(PcapSource, PublishesEncodedSweepsWithThePartialFlag) {
  SyntheticLidar lidar;
  Recording r;
  r.packets = 300;
  const std::string path = ::testing::TempDir() + "adit_pcap_source_" + std::to_string(::getpid()) + ".pcap";
  {
    std::ofstream f(path, std::ios::binary);
    f << writeRecording(lidar, r);
  }
  auto source = makePcapLidarSource(path, configOf(lidar));
  runtime::OutgoingMessage m;
  std::vector<LidarScan> sweeps;
  std::int64_t last_utime = 0;
  while (source->next(m)) {
    EXPECT_EQ(m.channel, "LIDAR_POINTS");
    EXPECT_GT(m.utime, last_utime);
    last_utime = m.utime;
    adit::lidar_scan_t msg;
    ASSERT_GT(msg.decode(m.data.data(), 0, static_cast<int>(m.data.size())), 0);
    LidarScan scan;
    ASSERT_EQ(msg::decodeSweep(msg, scan), "");
    sweeps.push_back(std::move(scan));
  }
  std::remove(path.c_str());
  ASSERT_EQ(sweeps.size(), 4u);
  EXPECT_FALSE(sweeps[2].partial);
  EXPECT_TRUE(sweeps[3].partial);
  EXPECT_GT(sweeps[1].points.size(), 20000u);
  EXPECT_DOUBLE_EQ(source->progress(), 1.0);
}

}  // namespace
}  // namespace adit::sources
