// VLP-16 and RS-16 packet decoding against packets written byte by byte (synthetic_lidar.cpp) and against
// hand-assembled bytes, plus malformed packets.
#include "drivers/rs16_decoder.hpp"
#include "drivers/vlp16_decoder.hpp"
#include "synthetic_lidar.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

namespace adit::drivers {
namespace {

using testing::Model;
using testing::SyntheticLidar;
using testing::TruthFiring;

PacketStatus decode(Model model, const std::vector<std::uint8_t>& bytes, DecodedPacket& out) {
  if (model == Model::kVlp16) return Vlp16Decoder().decode(bytes.data(), bytes.size(), out);
  return Rs16Decoder().decode(bytes.data(), bytes.size(), out);
}

// Decodes packets k0..k0+n-1 and compares every firing with the truth; returns the worst position error (m).
double checkAgainstTruth(const SyntheticLidar& lidar, int k0, int n) {
  double worst = 0.0;
  int returns = 0;
  for (int k = k0; k < k0 + n; ++k) {
    std::vector<TruthFiring> truth;
    const std::vector<std::uint8_t> bytes = lidar.packet(k, &truth);
    DecodedPacket d;
    EXPECT_EQ(decode(lidar.model, bytes, d), PacketStatus::kOk);
    EXPECT_EQ(d.stamp_us, lidar.stampUs(k));
    EXPECT_EQ(d.dual_return, lidar.dual);
    EXPECT_EQ(d.clock, lidar.model == Model::kVlp16 ? SensorClock::kMicrosPastHour : SensorClock::kUtcMicros);
    EXPECT_EQ(d.duration_ns, truth.back().offset_ns);
    EXPECT_EQ(d.firings.size(), truth.size());
    if (d.firings.size() != truth.size()) return 1e9;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const Firing& f = d.firings[i];
      const TruthFiring& t = truth[i];
      EXPECT_EQ(f.offset_ns, t.offset_ns) << "packet " << k << " firing " << i;
      const double daz = std::remainder(f.azimuth_deg - t.azimuth_deg, 360.0);
      EXPECT_LT(std::abs(daz), 1e-4) << "packet " << k << " firing " << i;
      EXPECT_EQ(f.ring, t.ring) << "laser " << t.laser;
      EXPECT_EQ(f.has_return, t.has_return) << "packet " << k << " firing " << i;
      if (!t.has_return) continue;
      ++returns;
      EXPECT_EQ(f.intensity, t.intensity);
      worst = std::max(worst, (f.p.cast<double>() - t.p).norm());
    }
  }
  EXPECT_GT(returns, 0);
  return worst;
}

TEST(Vlp16Decoder, EveryFiringMatchesTheSyntheticScene) {
  SyntheticLidar lidar;
  lidar.stamp0_us = 1234567;
  // 80 packets = 960 blocks > one revolution (900 blocks), so the azimuth wraps through 0 inside the run.
  const double worst = checkAgainstTruth(lidar, 0, 80);
  EXPECT_LT(worst, 1e-3);  // position within 1 mm (ranges up to 100 m)
  std::cout << "VLP-16 worst position error: " << worst * 1e3 << " mm\n";
}

TEST(Vlp16Decoder, DualReturnKeepsBothEchoesAndDropsRepeats) {
  SyntheticLidar lidar;
  lidar.dual = true;
  lidar.stamp0_us = 42;
  EXPECT_LT(checkAgainstTruth(lidar, 0, 20), 1e-3);
  // Both echoes of a firing share its time; the second one is dropped only when it repeats the first.
  std::vector<TruthFiring> truth;
  DecodedPacket d;
  ASSERT_EQ(decode(Model::kVlp16, lidar.packet(3, &truth), d), PacketStatus::kOk);
  ASSERT_EQ(d.firings.size(), 384u);
  int repeats = 0;
  for (std::size_t i = 0; i < d.firings.size(); i += 2) {
    EXPECT_EQ(d.firings[i].offset_ns, d.firings[i + 1].offset_ns);
    if (truth[i].range_m > 0 && truth[i + 1].range_m == truth[i].range_m) {
      ++repeats;
      EXPECT_FALSE(d.firings[i + 1].has_return);
    }
  }
  EXPECT_GT(repeats, 10);
}

TEST(Rs16Decoder, EveryFiringMatchesTheSyntheticScene) {
  SyntheticLidar lidar;
  lidar.model = Model::kRs16;
  lidar.stamp0_us = testing::kRs16TestEpochUs + 123456;
  const double worst = checkAgainstTruth(lidar, 0, 80);
  EXPECT_LT(worst, 1e-3);
  std::cout << "RS-16 worst position error: " << worst * 1e3 << " mm\n";
}

// Hand-assembled bytes pin byte order, units and the first firing's geometry.
TEST(Vlp16Decoder, HandAssembledBytes) {
  std::vector<std::uint8_t> p(1206, 0);
  for (int b = 0; b < 12; ++b) {
    p[b * 100] = 0xFF;
    p[b * 100 + 1] = 0xEE;
    p[b * 100 + 2] = 0x10;  // 0x2710 = 10000 -> 100.00 deg, little-endian
    p[b * 100 + 3] = 0x27;
  }
  p[4] = 0x1E;  // 0x031E = 798 x 2 mm = 1.596 m, laser 0 (-15 deg)
  p[5] = 0x03;
  p[6] = 100;
  p[7] = 0xE8;  // laser 1 (+1 deg): 0x03E8 = 1000 -> 2.000 m
  p[8] = 0x03;
  p[9] = 7;
  p[1200] = 0x40;  // 0x000F4240 = 1,000,000 us past the hour
  p[1201] = 0x42;
  p[1202] = 0x0F;
  p[1205] = 0x22;
  p[1204] = 0x37;
  DecodedPacket d;
  ASSERT_EQ(Vlp16Decoder().decode(p.data(), p.size(), d), PacketStatus::kOk);
  EXPECT_EQ(d.stamp_us, 1000000);
  const Firing& f = d.firings[0];
  ASSERT_TRUE(f.has_return);
  const double a = 100.0 * M_PI / 180, e = -15.0 * M_PI / 180;
  EXPECT_NEAR(f.p.x(), 1.596 * std::cos(e) * std::cos(a), 1e-6);
  EXPECT_NEAR(f.p.y(), -1.596 * std::cos(e) * std::sin(a), 1e-6);
  EXPECT_NEAR(f.p.z(), 1.596 * std::sin(e), 1e-6);
  EXPECT_EQ(f.ring, 0);
  EXPECT_EQ(f.intensity, 100.0f);
  const Firing& g = d.firings[1];
  EXPECT_EQ(g.offset_ns, 2304);
  EXPECT_NEAR(g.p.norm(), 2.0, 1e-6);
  EXPECT_NEAR(g.p.z(), 2.0 * std::sin(M_PI / 180), 1e-6);
  EXPECT_EQ(g.ring, 8);
  EXPECT_FALSE(d.firings[2].has_return);
}

TEST(Rs16Decoder, HandAssembledBytes) {
  std::vector<std::uint8_t> p(1248, 0);
  const std::uint8_t header[30] = {0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0, 0, 0, 0, 0, 0, 0, 0,
                                   0,    0,    0,    0,    0,    24,   3,    15,   10, 20, 30, 0x00, 0x7B, 0x01, 0xC8};
  std::copy(header, header + 30, p.begin());
  for (int b = 0; b < 12; ++b) {
    p[42 + b * 100] = 0xFF;
    p[42 + b * 100 + 1] = 0xEE;
    p[42 + b * 100 + 2] = 0x27;  // big-endian 0x2710 -> 100.00 deg
    p[42 + b * 100 + 3] = 0x10;
  }
  p[46] = 0x01;  // 0x013F = 319 x 5 mm = 1.595 m, channel 0 (-15 deg)
  p[47] = 0x3F;
  p[48] = 200;
  p[46 + 8 * 3] = 0x01;  // channel 8 (+15 deg): 0x0190 = 400 -> 2.000 m
  p[46 + 8 * 3 + 1] = 0x90;
  DecodedPacket d;
  ASSERT_EQ(Rs16Decoder().decode(p.data(), p.size(), d), PacketStatus::kOk);
  EXPECT_EQ(d.stamp_us, 1710498030LL * 1000000 + 123456);  // 2024-03-15 10:20:30.123456 UTC
  const Firing& f = d.firings[0];
  ASSERT_TRUE(f.has_return);
  const double a = 100.0 * M_PI / 180, e = -15.0 * M_PI / 180;
  EXPECT_NEAR(f.p.x(), 1.595 * std::cos(e) * std::cos(a), 1e-6);
  EXPECT_NEAR(f.p.y(), -1.595 * std::cos(e) * std::sin(a), 1e-6);
  EXPECT_NEAR(f.p.z(), 1.595 * std::sin(e), 1e-6);
  EXPECT_EQ(f.intensity, 200.0f);
  EXPECT_EQ(f.ring, 0);
  EXPECT_EQ(d.firings[8].offset_ns, 8 * 2800);
  EXPECT_NEAR(d.firings[8].p.z(), 2.0 * std::sin(15.0 * M_PI / 180), 1e-6);
  EXPECT_EQ(d.firings[8].ring, 15);
}

TEST(Rs16Decoder, UtcDates) {
  EXPECT_EQ(utcMicros(2000, 1, 1, 0, 0, 0, 0), 946684800LL * 1000000);
  EXPECT_EQ(utcMicros(2024, 2, 29, 23, 59, 59, 7), 1709251199LL * 1000000 + 7);
  EXPECT_EQ(utcMicros(2099, 12, 31, 23, 59, 59, 0), 4102444799LL * 1000000);
}

TEST(Decoders, CalibratedElevationTableMovesPointsAndRings) {
  SyntheticLidar lidar;
  std::vector<TruthFiring> truth;
  const auto bytes = lidar.packet(0, &truth);
  std::array<double, kBeams> table = kVlp16ElevationsDeg;
  table[0] = -14.5;  // laser 0 still lowest
  table[15] = -16.0; // laser 15 now lowest: rings shift
  DecodedPacket d;
  ASSERT_EQ(Vlp16Decoder(table).decode(bytes.data(), bytes.size(), d), PacketStatus::kOk);
  EXPECT_EQ(d.firings[15].ring, 0);
  EXPECT_EQ(d.firings[0].ring, 1);
  for (std::size_t i = 0; i < 16; ++i) {
    if (!truth[i].has_return) continue;
    const double elev = std::asin(d.firings[i].p.z() / d.firings[i].p.norm()) * 180 / M_PI;
    EXPECT_NEAR(elev, table[i], 1e-4);
  }
  table[3] = std::nan("");
  EXPECT_THROW(Vlp16Decoder{table}, std::invalid_argument);
}

TEST(Decoders, MalformedPacketsAreRejectedWithTheirReason) {
  SyntheticLidar vlp;
  SyntheticLidar rs;
  rs.model = Model::kRs16;
  rs.stamp0_us = testing::kRs16TestEpochUs;
  DecodedPacket d;
  auto bad = [&](Model m, std::vector<std::uint8_t> bytes) { return decode(m, bytes, d); };

  auto v = vlp.packet(0);
  EXPECT_EQ(bad(Model::kVlp16, {}), PacketStatus::kWrongSize);
  EXPECT_EQ(bad(Model::kVlp16, std::vector<std::uint8_t>(v.begin(), v.end() - 1)), PacketStatus::kWrongSize);
  EXPECT_EQ(bad(Model::kVlp16, rs.packet(0)), PacketStatus::kWrongSize);
  auto flag = v;
  flag[700] = 0xEF;  // block 7's flag
  EXPECT_EQ(bad(Model::kVlp16, flag), PacketStatus::kBadBlockFlag);
  auto az = v;
  az[302] = 0xA0;  // 0x8CA0 = 36000
  az[303] = 0x8C;
  EXPECT_EQ(bad(Model::kVlp16, az), PacketStatus::kBadAzimuth);
  auto product = v;
  product[1205] = 0x28;  // VLP-32C
  EXPECT_EQ(bad(Model::kVlp16, product), PacketStatus::kUnknownProduct);
  auto mode = v;
  mode[1204] = 0x40;
  EXPECT_EQ(bad(Model::kVlp16, mode), PacketStatus::kUnknownReturnMode);
  EXPECT_TRUE(d.firings.empty());

  auto r = rs.packet(0);
  EXPECT_EQ(bad(Model::kRs16, v), PacketStatus::kWrongSize);
  auto magic = r;
  magic[3] = 0x0B;
  EXPECT_EQ(bad(Model::kRs16, magic), PacketStatus::kBadMagic);
  auto date = r;
  date[21] = 13;  // month 13: decodes, but its stamp is flagged (the stream refuses it on sensor time)
  EXPECT_EQ(bad(Model::kRs16, date), PacketStatus::kOk);
  EXPECT_FALSE(d.stamp_valid);
  EXPECT_EQ(bad(Model::kRs16, r), PacketStatus::kOk);
  EXPECT_TRUE(d.stamp_valid);
  auto rflag = r;
  rflag[42 + 1100] = 0x00;  // block 11's flag
  EXPECT_EQ(bad(Model::kRs16, rflag), PacketStatus::kBadBlockFlag);

  // Random garbage of random sizes (some of the right size) never crashes and is never accepted.
  std::mt19937 rng(7);
  for (int i = 0; i < 2000; ++i) {
    std::vector<std::uint8_t> junk(i % 3 == 0 ? (i % 2 ? 1206 : 1248) : rng() % 3000);
    for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
    EXPECT_NE(bad(Model::kVlp16, junk), PacketStatus::kOk);
    EXPECT_NE(bad(Model::kRs16, junk), PacketStatus::kOk);
  }
}

}  // namespace
}  // namespace adit::drivers
