// The recording commands on good input, end to end with the built programs: `adit import pcap` of a capture
// the test writes itself (the synthetic VLP-16's packets, Linux cooked (SLL) link type as `tcpdump -i any`
// writes), `adit-lidar-bridge --source pcap --rate 0` publishing those sweeps through LCM (the file://
// provider: the live publishing path, no network needed), and `adit sim --pcap --bag` whose files `adit info`
// and `adit import pcap` read back.
#include "../drivers/synthetic_lidar.hpp"
#include "cli_helpers.hpp"
#include "io/capture_file.hpp"
#include "io/capture_writer.hpp"
#include "msg/sweep_codec.hpp"

#include <adit/lidar_scan_t.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace fs = std::filesystem;
using namespace adit::test;
using adit::drivers::testing::Model;
using adit::drivers::testing::SyntheticLidar;
using adit::drivers::testing::TruthFiring;

namespace {

constexpr std::int64_t kHost0Ns = 1700000000LL * 1000000000;  // capture clock at packet 0's first firing
constexpr int kPackets = 270;                                  // 3.6 revolutions at 10 Hz

// Linux cooked capture v1 header of an IPv4 packet received from the sensor: packet type 0 (to us), ARPHRD
// Ethernet, a 6-byte address, protocol 0x0800.
std::vector<std::uint8_t> sllFrame(const std::vector<std::uint8_t>& ip) {
  static const std::uint8_t header[16] = {0, 0, 0, 1, 0, 6, 0x60, 0x76, 0x88, 0x10, 0x20, 0x30, 0, 0, 0x08, 0x00};
  std::vector<std::uint8_t> f(header, header + 16);
  f.resize(16 + ip.size());
  std::copy(ip.begin(), ip.end(), f.begin() + 16);
  return f;
}

std::string writeCapture(const SyntheticLidar& lidar) {
  std::ostringstream out;
  adit::io::PcapWriter pcap(out, false, adit::io::kLinkLinuxSll);
  for (int k = 0; k < kPackets; ++k) {
    adit::io::UdpDatagram d;
    d.time_ns = kHost0Ns + k * lidar.packetNs() + lidar.lastFiringNs() + 100000;
    d.src_ip = 0xC0A801C9;  // 192.168.1.201, the VLP-16's factory address
    d.dst_ip = 0xC0A80164;
    d.src_port = d.dst_port = 2368;
    d.payload = lidar.packet(k);
    std::uint16_t ip_id = static_cast<std::uint16_t>(k);
    for (const auto& ip : adit::io::ipv4UdpPackets(d, ip_id)) pcap.writeFrame(d.time_ns, sllFrame(ip));
  }
  return out.str();
}

// Returns per revolution of the capture (between passes of the 180 deg cut) the firings with a return;
// the first entry began mid-revolution, the last is cut by the end of the capture.
std::vector<std::size_t> returnsPerRevolution(const SyntheticLidar& lidar) {
  std::vector<std::size_t> counts;
  const double start = lidar.az0_centideg / 100.0;
  for (int k = 0; k < kPackets; ++k) {
    std::vector<TruthFiring> truth;
    lidar.packet(k, &truth);
    for (const TruthFiring& f : truth) {
      const double unwrapped = (lidar.az0_centideg + lidar.gap_centideg * static_cast<double>(f.t_ns) /
                                                         static_cast<double>(lidar.blockNs())) / 100.0;
      const auto w = static_cast<std::size_t>(std::floor((unwrapped - 180.0) / 360.0) - std::floor((start - 180.0) / 360.0));
      if (counts.size() <= w) counts.resize(w + 1, 0);
      if (f.has_return) ++counts[w];
    }
  }
  return counts;
}

adit::LidarScan decoded(const std::vector<std::uint8_t>& bytes) {
  adit::lidar_scan_t msg;
  adit::LidarScan scan;
  EXPECT_GT(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  EXPECT_EQ(adit::msg::decodeSweep(msg, scan), "");
  return scan;
}

// The message count `adit info` prints on the line of a channel or topic: the first whole number after it.
long countInInfo(const std::string& info, const std::string& name) {
  std::istringstream lines(info);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string word;
    if (!(words >> word) || word != name) continue;
    while (words >> word)
      if (word.find_first_not_of("0123456789") == std::string::npos) return std::stol(word);
  }
  return -1;
}

class PcapCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = freshDir("pcap_cli");
    std::ofstream(dir_ / "drive.pcap", std::ios::binary) << writeCapture(lidar_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static SyntheticLidar lidar_;
  static fs::path dir_;
};
SyntheticLidar PcapCli::lidar_;
fs::path PcapCli::dir_;

}  // namespace

// Every complete revolution becomes a sweep with every return of it, 99.5 ms apart (the synthetic head's
// 0.4 deg per 55.3 us block); the first revolution, begun mid-way, is dropped as live; the one in progress at
// the end is published flagged partial.
TEST_F(PcapCli, ImportGivesEveryRevolutionOfTheCapture) {
  const fs::path log = dir_ / "import.lcmlog";
  ASSERT_EQ(run(bin("adit") + " import pcap " + (dir_ / "drive.pcap").string() + " --sensor vlp16 -o " + log.string(),
                dir_ / "import.txt"),
            0)
      << slurp(dir_ / "import.txt");
  const std::vector<std::size_t> returns = returnsPerRevolution(lidar_);
  ASSERT_EQ(returns.size(), 5u);  // 3.6 revolutions from 12.34 deg: cut passes at 180, 540, 900 and 1260 deg
  const auto sweeps = payloads(log.string()).at("LIDAR_POINTS");
  ASSERT_EQ(sweeps.size(), returns.size() - 1);
  for (std::size_t j = 0; j < sweeps.size(); ++j) {
    const adit::LidarScan s = decoded(sweeps[j]);
    const bool last = j + 1 == sweeps.size();
    EXPECT_EQ(s.partial, last) << "sweep " << j;
    EXPECT_EQ(s.num_beams, 16);
    EXPECT_TRUE(s.has_ring && s.has_time);
    EXPECT_EQ(s.points.size(), returns[j + 1]) << "sweep " << j;
    if (j > 0 && !last) {
      EXPECT_NEAR(static_cast<double>(s.utime - decoded(sweeps[j - 1]).utime), lidar_.rotationNs() / 1000.0, 2.0);
    }
  }
}

// The bridge's pcap source, as fast as it can, publishes through LCM the very sweeps the import wrote.
TEST_F(PcapCli, BridgePublishesTheSweepsOfTheCapture) {
  const fs::path imported = dir_ / "for_bridge.lcmlog", published = dir_ / "bridge.lcmlog";
  ASSERT_EQ(run(bin("adit") + " import pcap " + (dir_ / "drive.pcap").string() + " --sensor vlp16 -o " +
                    imported.string(),
                dir_ / "import_b.txt"),
            0);
  ASSERT_EQ(run(bin("adit-lidar-bridge") + " --source pcap --path " + (dir_ / "drive.pcap").string() +
                    " --sensor vlp16 --rate 0 --lcm-url 'file://" + published.string() + "?mode=w'",
                dir_ / "bridge.txt"),
            0)
      << slurp(dir_ / "bridge.txt");
  const auto p = payloads(published.string());
  ASSERT_TRUE(p.count("LIDAR_POINTS")) << slurp(dir_ / "bridge.txt");
  EXPECT_EQ(p.at("LIDAR_POINTS"), payloads(imported.string()).at("LIDAR_POINTS"));
  EXPECT_GE(p.count("STATUS_LIDAR_BRIDGE") ? p.at("STATUS_LIDAR_BRIDGE").size() : 0u, 1u);
}

// The 32-beam heads go the same way: `adit import pcap --sensor vlp32c|hdl32e`, and the bridge given only the
// sensor's launch/sensors file, give every revolution's returns as 32-beam sweeps.
TEST_F(PcapCli, ThirtyTwoBeamHeadsImportAndBridge) {
  for (const auto& [name, model] : {std::pair{"vlp32c", Model::kVlp32c}, std::pair{"hdl32e", Model::kHdl32e}}) {
    SyntheticLidar lidar;
    lidar.model = model;
    const fs::path capture = dir_ / (std::string(name) + ".pcap"), log = dir_ / (std::string(name) + ".lcmlog"),
                   published = dir_ / (std::string(name) + "_bridge.lcmlog");
    std::ofstream(capture, std::ios::binary) << writeCapture(lidar);
    ASSERT_EQ(run(bin("adit") + " import pcap " + capture.string() + " --sensor " + name + " -o " + log.string(),
                  dir_ / "import32.txt"),
              0)
        << slurp(dir_ / "import32.txt");
    const std::vector<std::size_t> returns = returnsPerRevolution(lidar);
    const auto sweeps = payloads(log.string()).at("LIDAR_POINTS");
    ASSERT_EQ(sweeps.size(), returns.size() - 1) << name;
    for (std::size_t j = 0; j < sweeps.size(); ++j) {
      const adit::LidarScan s = decoded(sweeps[j]);
      EXPECT_EQ(s.num_beams, 32) << name;
      EXPECT_EQ(s.sensor, name);
      EXPECT_EQ(s.points.size(), returns[j + 1]) << name << " sweep " << j;
    }
    // No --sensor: the sensor file's lidar_driver.model says which head sent the packets.
    ASSERT_EQ(run(bin("adit-lidar-bridge") + " --source pcap --path " + capture.string() +
                      " --driver-config " + ADIT_SOURCE_DIR + "/launch/sensors/" + name + ".yaml --rate 0 --lcm-url 'file://" +
                      published.string() + "?mode=w'",
                  dir_ / "bridge32.txt"),
              0)
        << slurp(dir_ / "bridge32.txt");
    EXPECT_EQ(payloads(published.string()).at("LIDAR_POINTS"), sweeps) << name;
  }
}

// The simulator's capture and bag are files the other commands read: `adit info` lists the bag's topics with
// the run's message counts, and the capture imports to the run's sweeps but its first (dropped as live).
TEST_F(PcapCli, SimulatorCaptureAndBagAreReadBack) {
  const fs::path sim = dir_ / "sim.lcmlog", pcap = dir_ / "sim.pcap", bag = dir_ / "sim.bag", back = dir_ / "sim_pcap.lcmlog";
  ASSERT_EQ(run(bin("adit") + " sim --world roadway-straight --duration 2 --seed 3 -o " + sim.string() + " --pcap " +
                    pcap.string() + " --bag " + bag.string(),
                dir_ / "sim.txt"),
            0)
      << slurp(dir_ / "sim.txt");
  const auto run_messages = payloads(sim.string());
  const long sweeps = static_cast<long>(run_messages.at("LIDAR_POINTS").size());
  const long imu = static_cast<long>(run_messages.at("IMU").size());
  ASSERT_EQ(sweeps, 20);  // 2 s at 10 Hz

  ASSERT_EQ(run(bin("adit") + " info " + bag.string(), dir_ / "info_bag.txt"), 0) << slurp(dir_ / "info_bag.txt");
  const std::string bag_info = slurp(dir_ / "info_bag.txt");
  EXPECT_EQ(countInInfo(bag_info, "/velodyne_points"), sweeps) << bag_info;
  EXPECT_EQ(countInInfo(bag_info, "/imu/data"), imu) << bag_info;

  ASSERT_EQ(run(bin("adit") + " import pcap " + pcap.string() + " --sensor vlp16 -o " + back.string(),
                dir_ / "import_sim.txt"),
            0)
      << slurp(dir_ / "import_sim.txt");
  ASSERT_EQ(run(bin("adit") + " info " + back.string(), dir_ / "info_pcap.txt"), 0) << slurp(dir_ / "info_pcap.txt");
  EXPECT_EQ(countInInfo(slurp(dir_ / "info_pcap.txt"), "LIDAR_POINTS"), sweeps - 1) << slurp(dir_ / "info_pcap.txt");
}
