// Recorded captures -> sweeps (CaptureLidarReader: capture reader, UDP extraction, the live driver's
// LidarPacketStream): a pcap written from the synthetic lidar's known firings, with a lost packet, a reordered
// pair (put back in order), a fragmented datagram and foreign traffic, decodes to those firings (position within 1 mm, ring exact,
// time to the sensor stamp's microsecond); the last revolution comes out flagged partial.
#include "io/capture_writer.hpp"
#include "msg/sweep_codec.hpp"
#include "runtime/source.hpp"
#include "sources/capture_lidar_reader.hpp"
#include "sources/pcap_source.hpp"
#include "pcap_recording.hpp"
#include "synthetic_lidar.hpp"

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
using namespace adit::sources::testing;  // NOLINT(google-build-using-namespace): the shared recording helpers

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
  lidar.stamp0_us = lidar.model == Model::kRs16 ? drivers::testing::kRs16TestEpochUs + 5 : 777777;
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
  expectPointsMatchTruth(lidar, r, d.sweeps);
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
                                           Case{"rs16", Model::kRs16, false}, Case{"rs16_dual", Model::kRs16, true},
                                           Case{"vlp32c", Model::kVlp32c, false}, Case{"vlp32c_dual", Model::kVlp32c, true},
                                           Case{"hdl32e", Model::kHdl32e, false}),
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
  expectPointsMatchTruth(lidar, r, mine.sweeps);
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
  expectPointsMatchTruth(lidar, r, accepted.sweeps);
}

TEST(PcapRecording, APacketLaterThanTheReorderWindowIsSkipped) {
  SyntheticLidar lidar;
  Recording r;
  r.packets = 200;
  r.late = 60;
  const Decoded d = decode(writeRecording(lidar, r), configOf(lidar));
  EXPECT_EQ(d.health.counters.at("time_backwards"), 1);
  ASSERT_GE(d.sweeps.size(), 2u);
  expectPointsMatchTruth(lidar, r, d.sweeps);
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
  expectPointsMatchTruth(lidar, r, d.sweeps);
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
  expectPointsMatchTruth(lidar, r, d.sweeps);
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

// The message source the bridge and `adit import pcap` run: compact sweeps (the bus's encoding, decoded back)
// holding the known firings, ring and time exact, the last one flagged partial. Single-return 16-beam sweeps
// go in the firing-grid layout (1 mm); a VLP-32C's (each laser has its own horizontal offset, which the grid
// has no field for) and dual-return ones (two echoes per firing) fall back to the per-point layout, whose
// promise is msg::sweepTolerance (0.5 range count + 1e-4 rad: 1 cm at 90 m) and times to 1/65535 of the sweep.
struct SourceCase {
  const char* name;
  Model model;
  bool dual, grid;
};

class PcapSource : public ::testing::TestWithParam<SourceCase> {};

TEST_P(PcapSource, PublishesEncodedSweepsOfTheKnownFiringsWithThePartialFlag) {
  SyntheticLidar lidar;
  lidar.model = GetParam().model;
  lidar.dual = GetParam().dual;
  Recording r;
  r.packets = static_cast<int>(3.6 * lidar.rotationNs() / static_cast<double>(lidar.packetNs()));
  r.lost = 40;
  r.fragmented = 150;
  const std::string path = ::testing::TempDir() + "adit_pcap_source_" + GetParam().name + "_" + std::to_string(::getpid()) + ".pcap";
  {
    std::ofstream f(path, std::ios::binary);
    f << writeRecording(lidar, r);
  }
  auto source = makePcapLidarSource(path, configOf(lidar));
  const std::vector<LidarScan> sweeps = publishedSweeps(*source);
  std::remove(path.c_str());
  ASSERT_EQ(sweeps.size(), 4u);
  EXPECT_FALSE(sweeps[2].partial);
  EXPECT_TRUE(sweeps[3].partial);
  EXPECT_EQ(sweeps[1].num_beams, drivers::testing::beamsOf(lidar.model));
  Tolerance tolerance;  // 1 mm, the stamps' microsecond
  if (!GetParam().grid) {
    tolerance.position_m = [](double range) { return msg::sweepTolerance(range, msg::kRangeScale); };
    tolerance.time_ns += 0.5 * 0.1e9 / 65535;  // and half a time count (1/65535 of a sweep of <= 0.1 s)
  }
  expectPointsMatchTruth(lidar, r, sweeps, tolerance);
  EXPECT_DOUBLE_EQ(source->progress(), 1.0);
}

INSTANTIATE_TEST_SUITE_P(Sensors, PcapSource,
                         ::testing::Values(SourceCase{"vlp16", Model::kVlp16, false, true},
                                           SourceCase{"vlp16_dual", Model::kVlp16, true, false},
                                           SourceCase{"vlp32c", Model::kVlp32c, false, false},
                                           SourceCase{"vlp32c_dual", Model::kVlp32c, true, false}),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace adit::sources
