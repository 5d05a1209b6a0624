// End to end over real UDP: synthetic VLP-16 packets sent to 127.0.0.1 (unicast loopback, a random high
// port) reach makeUdpLidarSource, which must yield the same sweeps as the packets decoded offline, as
// encoded point_cloud_t messages. Bounded: a fixed number of packets, then the source's idle timeout ends it.
#include "drivers/lidar_stream.hpp"
#include "drivers/udp_lidar_source.hpp"
#include "drivers/udp_sender.hpp"
#include "msg/convert.hpp"
#include "msg/sweep_codec.hpp"
#include "synthetic_lidar.hpp"


#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cmath>
#include <chrono>
#include <random>
#include <thread>

namespace adit::drivers {
namespace {

using testing::SyntheticLidar;

// Sends `packets` to 127.0.0.1:port, one every `spacing` (a real VLP-16 sends one per 1.33 ms).
void sendPackets(const std::vector<std::vector<std::uint8_t>>& packets, std::uint16_t port,
                 std::chrono::microseconds spacing) {
  UdpSender sender("127.0.0.1", port);
  auto due = std::chrono::steady_clock::now();
  for (const auto& p : packets) {
    std::this_thread::sleep_until(due);
    due += spacing;
    std::string error;
    ASSERT_TRUE(sender.send(p.data(), p.size(), error)) << error;
  }
}

// Binds the source on random high ports (another program may hold one, so try a few); RS-16: the DIFOP
// port too.
std::unique_ptr<runtime::MessageSource> bindOnRandomPorts(UdpLidarConfig& config) {
  std::mt19937 rng(std::random_device{}());
  for (int attempt = 0; attempt < 20; ++attempt) {
    config.port = 20000 + static_cast<int>(rng() % 40000);
    if (config.model == "rs16") config.difop_port = 20000 + static_cast<int>(rng() % 40000);
    try {
      return makeUdpLidarSource(config, [] { return false; });
    } catch (const std::runtime_error&) {
    }
  }
  return nullptr;
}

TEST(UdpLidarSource, SweepsFromRealUdpPackets) {
  SyntheticLidar lidar;
  lidar.stamp0_us = 3599000000LL;  // crosses the sensor's hour wrap on the way
  const int n = 270;               // 3.6 revolutions -> 3 complete sweeps
  std::vector<std::vector<std::uint8_t>> packets;
  for (int k = 0; k < n; ++k) packets.push_back(lidar.packet(k));
  packets.insert(packets.begin() + 100, std::vector<std::uint8_t>(512, 0xAB));  // a stray datagram

  // Offline reference: the same packets through the pure stream.
  UdpLidarConfig config;
  config.idle_timeout_s = 0.5;
  config.bind_address = "127.0.0.1";  // loopback only: nothing from the network reaches the test
  std::vector<LidarScan> expected;
  {
    LidarPacketStream stream(streamConfigOf(config));
    std::int64_t t = 1000000000000000000LL;
    for (const auto& p : packets) stream.push(p.data(), p.size(), t += 1327104, expected);
  }
  ASSERT_EQ(expected.size(), 3u);

  std::unique_ptr<runtime::MessageSource> source = bindOnRandomPorts(config);
  ASSERT_TRUE(source) << "no free UDP port";

  // Not faster than the sensor sends them (1327 us): its stamps are mapped onto the receive times, and
  // packets arriving faster than its clock runs would read as a clock running fast. Slower reads as a sensor
  // clock running slow, held by the offset filter at the least-delayed packet (the first): the mapping of
  // the reference, whose receive times are exactly the sensor's spacing.
  std::thread sender(sendPackets, std::cref(packets), static_cast<std::uint16_t>(config.port),
                     std::chrono::microseconds(1400));
  std::vector<runtime::OutgoingMessage> messages;
  runtime::OutgoingMessage m;
  const auto start = std::chrono::steady_clock::now();
  while (source->next(m)) messages.push_back(m);  // ends 0.5 s after the last packet
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  sender.join();

  const runtime::Health& h = source->health();
  EXPECT_EQ(h.inputs, n + 1) << "datagrams lost on loopback";
  EXPECT_EQ(h.errors, 1);
  EXPECT_EQ(h.counters.at("wrong_size"), 1);
  EXPECT_EQ(h.outputs, 3);
  ASSERT_EQ(messages.size(), expected.size());
  for (std::size_t j = 0; j < messages.size(); ++j) {
    EXPECT_EQ(messages[j].channel, "LIDAR_POINTS");
    // The bridge writes compact sweeps in the firing-grid layout (the driver's firing table).
    adit::lidar_scan_t msg;
    ASSERT_GE(msg.decode(messages[j].data.data(), 0, static_cast<int>(messages[j].data.size())), 0);
    EXPECT_EQ(msg.layout, +adit::lidar_scan_t::LAYOUT_GRID);
    LidarScan s;
    ASSERT_EQ(msg::decodeSweep(msg, s), "");
    const LidarScan& e = expected[j];
    EXPECT_EQ(messages[j].utime, s.utime);
    EXPECT_EQ(s.seq, e.seq);
    EXPECT_EQ(s.sensor, "vlp16");
    EXPECT_EQ(s.num_beams, 16);
    EXPECT_TRUE(s.has_ring && s.has_time);
    // Sweeps are anchored on the receive time of the first packet: compare the spacing, not the origin.
    if (j > 0) {
      EXPECT_EQ(s.utime - messages[j - 1].utime, e.utime - expected[j - 1].utime);
    }
    EXPECT_NEAR(s.sweep_duration, e.sweep_duration, 1e-7);
    ASSERT_EQ(s.points.size(), e.points.size());
    for (std::size_t i = 0; i < e.points.size(); ++i) {
      // Within the packets' own resolution: 2 mm ranges, 0.01 deg azimuths; times to the nanosecond.
      EXPECT_LE((s.points[i].p - e.points[i].p).norm(), msg::sweepTolerance(e.points[i].p.norm(), msg.range_scale));
      EXPECT_EQ(s.points[i].ring, e.points[i].ring);
      EXPECT_EQ(s.points[i].intensity, e.points[i].intensity);
      EXPECT_NEAR(s.points[i].dt, e.points[i].dt, 1e-8);
    }
  }
  // utime is host time (us since 1970): within a minute of now.
  const auto now_us = std::chrono::duration_cast<std::chrono::microseconds>(
                          std::chrono::system_clock::now().time_since_epoch()).count();
  EXPECT_LT(std::abs(messages.back().utime - now_us), 60000000);
  std::cout << n << " packets over UDP -> " << messages.size() << " sweeps in " << seconds << " s\n";
}

// A live RS-16 sends its calibration (DIFOP) to its own port once a second: the bridge listens there too, and
// the calibrated vertical angles replace the nominal ones from the first sweep on.
TEST(UdpLidarSource, Rs16DifopOnItsOwnPortCalibratesLiveSweeps) {
  SyntheticLidar lidar;
  lidar.model = testing::Model::kRs16;
  lidar.stamp0_us = testing::kRs16TestEpochUs;
  const int n = static_cast<int>(3.6 * lidar.rotationNs() / static_cast<double>(lidar.packetNs()));
  std::vector<std::vector<std::uint8_t>> packets;
  for (int k = 0; k < n; ++k) packets.push_back(lidar.packet(k));
  std::array<double, 16> calibrated = testing::nominalRs16Elevations();
  for (std::size_t i = 0; i < 16; ++i) calibrated[i] += (i < 8 ? -0.137 : 0.211);

  UdpLidarConfig config;
  config.model = "rs16";
  config.idle_timeout_s = 0.5;
  config.bind_address = "127.0.0.1";
  std::unique_ptr<runtime::MessageSource> source = bindOnRandomPorts(config);
  ASSERT_TRUE(source) << "no free UDP port";
  sendPackets({testing::rs16DifopPacket(false, calibrated)}, static_cast<std::uint16_t>(config.difop_port),
              std::chrono::microseconds(0));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the DIFOP is waiting before the data comes
  std::thread sender(sendPackets, std::cref(packets), static_cast<std::uint16_t>(config.port),
                     std::chrono::microseconds(500));
  std::vector<LidarScan> sweeps;
  runtime::OutgoingMessage m;
  while (source->next(m)) {
    adit::lidar_scan_t msg;
    ASSERT_GE(msg.decode(m.data.data(), 0, static_cast<int>(m.data.size())), 0);
    sweeps.emplace_back();
    ASSERT_EQ(msg::decodeSweep(msg, sweeps.back()), "");
  }
  sender.join();

  const runtime::Health& h = source->health();
  EXPECT_EQ(h.counters.at("difop"), 1);
  EXPECT_EQ(h.counters.at("difop_applied"), 1);
  ASSERT_EQ(sweeps.size(), 3u);
  std::size_t checked = 0;
  for (const LidarScan& sweep : sweeps)
    for (const LidarPoint& p : sweep.points) {
      // RS-16 rings 0..7 are lasers 0..7, rings 8..15 lasers 15..8. The offsets are 0.14-0.21 deg; the
      // compact sweep keeps directions to a few thousandths of a degree.
      const std::size_t laser = p.ring < 8 ? p.ring : 23u - p.ring;
      EXPECT_NEAR(std::asin(p.p.z() / p.p.norm()) * 180.0 / M_PI, calibrated[laser], 0.02);
      ++checked;
    }
  EXPECT_GT(checked, 20000u);
}

TEST(UdpLidarSource, BadConfigIsRefusedUpFront) {
  UdpLidarConfig c;
  c.model = "hdl64";
  EXPECT_THROW(makeUdpLidarSource(c), std::invalid_argument);
  c = UdpLidarConfig{};
  c.time_source = "gps";
  EXPECT_THROW(makeUdpLidarSource(c), std::invalid_argument);
  c = UdpLidarConfig{};
  c.vertical_angles_deg = {1, 2, 3};
  EXPECT_THROW(makeUdpLidarSource(c), std::invalid_argument);
  c = UdpLidarConfig{};
  c.model = "rs16";
  c.difop_port = 70000;
  EXPECT_THROW(makeUdpLidarSource(c), std::invalid_argument);
  c = UdpLidarConfig{};
  c.bind_address = "not-an-address";
  c.port = 1;
  EXPECT_THROW(makeUdpLidarSource(c), std::runtime_error);
}

TEST(UdpLidarSource, ConfigKeys) {
  const Config c = Config::fromYamlString(
      "lidar_driver:\n  model: rs16\n  port: 7000\n  time_source: host\n  cut_azimuth_deg: 90\n"
      "  vertical_angles_deg: [-15.1, -13, -11, -9, -7, -5, -3, -1, 15, 13, 11, 9, 7, 5, 3, 1.2]\n"
      "  idle_timeout_s: 2\n  channel: LIDAR_RS\n");
  const UdpLidarConfig d = udpLidarConfigFrom(c);
  EXPECT_EQ(d.model, "rs16");
  EXPECT_EQ(d.port, 7000);
  EXPECT_EQ(d.channel, "LIDAR_RS");
  ASSERT_EQ(d.vertical_angles_deg.size(), 16u);
  EXPECT_DOUBLE_EQ(d.vertical_angles_deg[0], -15.1);
  const LidarStreamConfig s = streamConfigOf(d);
  EXPECT_EQ(s.model, LidarModel::kRs16);
  EXPECT_EQ(s.clock.source, TimeSource::kHost);
  EXPECT_EQ(s.sweep.cut_azimuth_deg, 90.0);
  EXPECT_EQ(s.sweep.sensor, "rs16");
  const UdpLidarConfig defaults = udpLidarConfigFrom(Config{});
  EXPECT_EQ(dataPortOf(defaults), 2368);
  EXPECT_EQ(defaults.time_source, "sensor");
  EXPECT_EQ(defaults.cut_azimuth_deg, 180.0);
  EXPECT_EQ(dataPortOf(d), 7000);
  UdpLidarConfig rs;
  rs.model = "rs16";
  EXPECT_EQ(dataPortOf(rs), 6699);
}

}  // namespace
}  // namespace adit::drivers

namespace adit::drivers {
namespace {

TEST(UdpSender, AddressesAreIpv4HostAndPort) {
  std::string host;
  std::uint16_t port = 0;
  parseUdpAddress("127.0.0.1:2368", host, port);
  EXPECT_EQ(host, "127.0.0.1");
  EXPECT_EQ(port, 2368);
  for (const char* bad : {"127.0.0.1", ":2368", "127.0.0.1:", "127.0.0.1:0", "127.0.0.1:65536", "127.0.0.1:23x",
                          "localhost:2368", "127.0.0.1:2368:1"})
    EXPECT_THROW(parseUdpAddress(bad, host, port), std::invalid_argument) << bad;
  EXPECT_THROW(UdpSender("not-an-address", 2368), std::runtime_error);
}

}  // namespace
}  // namespace adit::drivers
