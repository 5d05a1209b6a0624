// VLP-32C and HDL-32E captures: packets written here byte by byte from the manuals' layouts (one firing
// sequence of 32 lasers per block; VLP-32C: pairs 2.304 us apart, 4 mm counts, +-1.4 / +-4.2 deg horizontal
// offsets; HDL-32E: 1.152 us apart, 2 mm counts), decoded through the capture reader and the live driver's
// stream: every point at its firing's position (1 mm), ring (rank of elevation) and time (stamp microsecond).
#include "io/capture_writer.hpp"
#include "sources/capture_lidar_reader.hpp"
#include "synthetic_lidar.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

namespace adit::sources {
namespace {

struct Head {
  const char* name;
  std::vector<double> elevation, delta;  // by laser id (deg)
  std::int64_t sequence_ns, pair_ns;     // laser i fires at (i / lasers_per_slot) * slot_ns
  int lasers_per_slot;
  double unit_m;
  std::uint8_t product;
};

// The manuals' tables (VLP-32C 63-9325 tables 9-2 / 9-5, HDL-32E 63-9113), as the synthetic lidar has them.
Head headOf(const char* name, drivers::testing::Model model, std::int64_t sequence_ns, std::int64_t pair_ns,
            int lasers_per_slot, double unit_m, std::uint8_t product) {
  Head h{name, {}, {}, sequence_ns, pair_ns, lasers_per_slot, unit_m, product};
  for (int i = 0; i < 32; ++i) {
    h.elevation.push_back(drivers::testing::elevationDeg(model, i));
    h.delta.push_back(drivers::testing::azimuthOffsetDeg(model, i));
  }
  return h;
}

Head vlp32c() { return headOf("vlp32c", drivers::testing::Model::kVlp32c, 55296, 2304, 2, 0.004, 0x28); }
Head hdl32e() { return headOf("hdl32e", drivers::testing::Model::kHdl32e, 46080, 1152, 1, 0.002, 0x21); }

struct Truth {
  std::int64_t t_ns;
  int ring;
  Eigen::Vector3d p;
  double head_deg;  // the head's azimuth at the firing, unwrapped
  bool used = false;
};

constexpr int kGapCentiDeg = 35;  // azimuth per block (one sequence)

// Packet k and its truth firings with returns (time since packet 0's first firing).
std::vector<std::uint8_t> packet(const Head& h, int k, std::vector<Truth>& truth) {
  std::vector<int> rank(32);
  std::iota(rank.begin(), rank.end(), 0);
  std::stable_sort(rank.begin(), rank.end(), [&h](int a, int b) { return h.elevation[a] < h.elevation[b]; });
  std::vector<int> ring(32);
  for (int r = 0; r < 32; ++r) ring[rank[r]] = r;
  std::vector<std::uint8_t> p(1206, 0);
  for (int b = 0; b < 12; ++b) {
    const int n = k * 12 + b;
    const int az = (500 + kGapCentiDeg * n) % 36000;
    p[b * 100] = 0xFF;
    p[b * 100 + 1] = 0xEE;
    p[b * 100 + 2] = static_cast<std::uint8_t>(az & 0xFF);
    p[b * 100 + 3] = static_cast<std::uint8_t>(az >> 8);
    for (int i = 0; i < 32; ++i) {
      const unsigned raw = (n * 131 + i * 977) % 9 == 0 ? 0u : static_cast<unsigned>(1000 + (n * 37 + i * 1013) % 20000);
      p[b * 100 + 4 + i * 3] = static_cast<std::uint8_t>(raw & 0xFF);
      p[b * 100 + 5 + i * 3] = static_cast<std::uint8_t>(raw >> 8);
      p[b * 100 + 6 + i * 3] = static_cast<std::uint8_t>(i * 7);
      if (raw == 0) continue;
      const std::int64_t in_block = (i / h.lasers_per_slot) * h.pair_ns;
      const double head = (500 + kGapCentiDeg * (n + static_cast<double>(in_block) / h.sequence_ns)) / 100.0;
      const double e = h.elevation[i] * M_PI / 180.0, ar = (head + h.delta[i]) * M_PI / 180.0, r = raw * h.unit_m;
      truth.push_back({n * h.sequence_ns + in_block, ring[i],
                       Eigen::Vector3d(r * std::cos(e) * std::cos(ar), -r * std::cos(e) * std::sin(ar), r * std::sin(e)),
                       head});
    }
  }
  const std::uint32_t stamp = static_cast<std::uint32_t>(2000000 + k * 12 * h.sequence_ns / 1000);
  for (int i = 0; i < 4; ++i) p[1200 + i] = static_cast<std::uint8_t>(stamp >> (8 * i));
  p[1204] = 0x37;
  p[1205] = h.product;
  return p;
}

void PrintTo(const Head& h, std::ostream* os) { *os << h.name; }

class Pcap32 : public ::testing::TestWithParam<Head> {};

TEST_P(Pcap32, EveryPointAtItsFiring) {
  const Head& h = GetParam();
  const int packets = static_cast<int>(2.6 * 36000 / kGapCentiDeg / 12);  // 2.6 revolutions
  std::ostringstream out;
  io::PcapWriter pcap(out);
  std::vector<Truth> truth;
  const std::int64_t t0 = 1700000000LL * 1000000000;
  for (int k = 0; k < packets; ++k) {
    io::UdpDatagram d;
    d.payload = packet(h, k, truth);
    d.time_ns = t0 + k * 12 * h.sequence_ns + 11 * h.sequence_ns + (31 / h.lasers_per_slot) * h.pair_ns;  // last firing
    d.src_ip = 0xC0A801C9;
    d.dst_ip = 0xC0A80164;
    d.src_port = d.dst_port = 2368;
    pcap.writeUdp(d);
  }
  drivers::UdpLidarConfig config;
  config.model = h.name;
  std::istringstream in(out.str());
  CaptureLidarReader reader(in, "t.pcap", config);
  std::vector<LidarScan> sweeps;
  while (reader.read(sweeps)) {
  }
  ASSERT_EQ(sweeps.size(), 3u);  // 2 complete + the partial end
  EXPECT_EQ(reader.health().errors, 0);
  std::size_t matched = 0;
  for (const LidarScan& s : sweeps) {
    EXPECT_EQ(s.num_beams, 32);
    EXPECT_EQ(s.sensor, h.name);
    for (const LidarPoint& p : s.points) {
      const double t = static_cast<double>(s.utime * 1000 - t0) + p.dt * 1e9;
      auto it = std::find_if(truth.begin(), truth.end(), [&](const Truth& f) {
        return !f.used && f.ring == p.ring && std::abs(static_cast<double>(f.t_ns) - t) < 2500.0 &&
               (f.p - p.p.cast<double>()).norm() < 1e-3;
      });
      ASSERT_NE(it, truth.end()) << h.name << ": no firing of ring " << p.ring << " at " << t << " ns " << p.p.transpose();
      it->used = true;
      ++matched;
    }
  }
  // Everything from the first pass of the cut (180 deg) on: the revolution before it began mid-way.
  const auto expected = std::count_if(truth.begin(), truth.end(), [](const Truth& f) { return f.head_deg >= 180.0; });
  EXPECT_EQ(matched, static_cast<std::size_t>(expected));
}

INSTANTIATE_TEST_SUITE_P(Heads, Pcap32, ::testing::Values(vlp32c(), hdl32e()),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace adit::sources
