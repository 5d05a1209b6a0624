#include "synthetic_lidar.hpp"

#include <algorithm>
#include <cmath>

namespace adit::drivers::testing {
namespace {

std::uint64_t mix(std::uint64_t x) {  // splitmix64 finaliser: a deterministic hash
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

void putLe16(std::uint8_t* p, unsigned v) { p[0] = v & 0xFF; p[1] = (v >> 8) & 0xFF; }
void putBe16(std::uint8_t* p, unsigned v) { p[0] = (v >> 8) & 0xFF; p[1] = v & 0xFF; }

}  // namespace

double elevationDeg(Model model, int laser) {
  if (model == Model::kVlp16) return laser % 2 == 0 ? -15.0 + laser : static_cast<double>(laser);
  return laser < 8 ? -15.0 + 2 * laser : 15.0 - 2 * (laser - 8);
}

int ringOf(Model model, int laser) {
  if (model == Model::kVlp16) return laser % 2 == 0 ? laser / 2 : 8 + laser / 2;
  return laser < 8 ? laser : 23 - laser;
}

// RS-16 dual return: one sequence per block (both echoes in it), so a block is one sequence long.
std::int64_t SyntheticLidar::blockNs() const { return model == Model::kVlp16 ? 110592 : dual ? 55500 : 111000; }
int SyntheticLidar::groupsPerPacket() const { return dual && model == Model::kVlp16 ? 6 : 12; }
std::int64_t SyntheticLidar::lastFiringNs() const {
  if (model == Model::kVlp16) return packetNs() - blockNs() + 55296 + 15 * 2304;
  return packetNs() - blockNs() + (dual ? 0 : 55500) + 15 * 2800;
}

std::int64_t SyntheticLidar::stampUs(int k) const {
  const std::int64_t us = stamp0_us + (static_cast<std::int64_t>(k) * packetNs()) / 1000;  // whole us, truncated
  return model == Model::kVlp16 ? us % 3600000000LL : us;
}

std::vector<std::uint8_t> SyntheticLidar::packet(int k, std::vector<TruthFiring>* truth) const {
  const bool vlp = model == Model::kVlp16;
  const std::size_t header = vlp ? 0 : 42;
  std::vector<std::uint8_t> bytes(vlp ? 1206 : 1248, 0);
  const double unit = vlp ? 0.002 : 0.005;
  const std::int64_t sequence_ns = vlp ? 55296 : 55500, firing_ns = vlp ? 2304 : 2800;
  const int returns = dual ? 2 : 1;
  // VLP-16 dual: block pairs (one per echo) of two sequences; RS-16 dual: one block of one sequence whose
  // slots 0..15 hold the first echo and 16..31 the second.
  const bool rs_dual = !vlp && dual;
  const int blocks_per_group = rs_dual ? 1 : returns, sequences = rs_dual ? 1 : 2;
  for (int g = 0; g < groupsPerPacket(); ++g) {
    const std::int64_t n = static_cast<std::int64_t>(k) * groupsPerPacket() + g;  // global block (group) index
    const int az_raw = static_cast<int>((az0_centideg + gap_centideg * n) % 36000);
    for (int r = 0; r < blocks_per_group; ++r) {
      std::uint8_t* block = bytes.data() + header + static_cast<std::size_t>((g * blocks_per_group + r) * 100);
      block[0] = 0xFF;
      block[1] = 0xEE;
      vlp ? putLe16(block + 2, az_raw) : putBe16(block + 2, az_raw);
    }
    for (int s = 0; s < sequences; ++s) {
      for (int laser = 0; laser < 16; ++laser) {
        const std::int64_t in_block = s * sequence_ns + laser * firing_ns;
        unsigned first_raw = 0;
        for (int r = 0; r < returns; ++r) {
          const std::uint64_t h = mix(seed ^ mix(static_cast<std::uint64_t>(n * 64 + s * 16 + laser) * 4 + r));
          const double u = static_cast<double>(h >> 11) / 9007199254740992.0;  // [0, 1)
          unsigned raw = static_cast<unsigned>(std::lround((0.5 + 99.5 * u) / unit));
          if (r == 1 && (h & 3) == 0) raw = first_raw;  // strongest echo == last echo
          if (static_cast<double>(mix(h) >> 11) / 9007199254740992.0 < no_return_fraction) raw = 0;
          if (r == 0) first_raw = raw;
          const int intensity = static_cast<int>((h >> 3) & 0xFF);
          const int block = rs_dual ? g : g * returns + r, slot = rs_dual ? r * 16 + laser : s * 16 + laser;
          std::uint8_t* point = bytes.data() + header + static_cast<std::size_t>(block * 100 + 4 + slot * 3);
          vlp ? putLe16(point, raw) : putBe16(point, raw);
          point[2] = static_cast<std::uint8_t>(intensity);
          if (truth == nullptr) continue;
          TruthFiring f;
          f.offset_ns = g * blockNs() + in_block;
          f.t_ns = static_cast<std::int64_t>(k) * packetNs() + f.offset_ns;
          const double az = az0_centideg + gap_centideg * (static_cast<double>(n) + static_cast<double>(in_block) /
                                                                                       static_cast<double>(blockNs()));
          f.azimuth_deg = std::fmod(az, 36000.0) / 100.0;
          f.laser = laser;
          f.ring = ringOf(model, laser);
          f.range_m = raw * unit;
          f.intensity = intensity;
          f.has_return = raw != 0 && !(r == 1 && raw == first_raw);
          const double e = elevationDeg(model, laser) * M_PI / 180.0, a = f.azimuth_deg * M_PI / 180.0;
          if (f.has_return)
            f.p = {f.range_m * std::cos(e) * std::cos(a), -f.range_m * std::cos(e) * std::sin(a),
                   f.range_m * std::sin(e)};
          truth->push_back(f);
        }
      }
    }
  }
  const std::int64_t stamp = stampUs(k);
  if (vlp) {
    for (int i = 0; i < 4; ++i) bytes[1200 + i] = static_cast<std::uint8_t>((stamp >> (8 * i)) & 0xFF);
    bytes[1204] = dual ? 0x39 : 0x37;
    bytes[1205] = 0x22;
  } else {
    const std::uint8_t magic[8] = {0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0};
    for (int i = 0; i < 8; ++i) bytes[i] = magic[i];
    // Date and time of `stamp` (UTC us); the tests stay within 2024-03-15.
    const std::int64_t since_epoch_day = stamp - (kRs16TestEpochUs - (10 * 3600 + 20 * 60 + 30) * 1000000LL);
    const std::int64_t day_us = 86400LL * 1000000;
    const std::int64_t in_day = since_epoch_day % day_us;
    const int day = 15 + static_cast<int>(since_epoch_day / day_us);
    const std::int64_t seconds = in_day / 1000000;
    const int micros = static_cast<int>(in_day % 1000000);
    bytes[20] = 24;
    bytes[21] = 3;
    bytes[22] = static_cast<std::uint8_t>(day);
    bytes[23] = static_cast<std::uint8_t>(seconds / 3600);
    bytes[24] = static_cast<std::uint8_t>((seconds / 60) % 60);
    bytes[25] = static_cast<std::uint8_t>(seconds % 60);
    putBe16(bytes.data() + 26, static_cast<unsigned>(micros / 1000));
    putBe16(bytes.data() + 28, static_cast<unsigned>(micros % 1000));
    bytes[1246] = 0x00;
    bytes[1247] = 0xFF;
  }
  return bytes;
}

std::vector<std::uint8_t> rs16DifopPacket(bool dual, const std::array<double, 16>& elevation_deg) {
  std::vector<std::uint8_t> p(1248, 0);
  const std::uint8_t magic[8] = {0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};
  std::copy(magic, magic + 8, p.begin());
  p[300] = dual ? 0 : 1;
  for (std::size_t i = 0; i < 16; ++i) {
    const auto v = static_cast<std::uint32_t>(std::lround(std::abs(elevation_deg[i]) * 1000.0));
    p[1165 + 3 * i] = static_cast<std::uint8_t>(v >> 16);
    p[1166 + 3 * i] = static_cast<std::uint8_t>(v >> 8);
    p[1167 + 3 * i] = static_cast<std::uint8_t>(v);
  }
  p[1246] = 0x0F;
  p[1247] = 0xF0;
  return p;
}

std::array<double, 16> nominalRs16Elevations() {
  std::array<double, 16> e{};
  for (int i = 0; i < 16; ++i) e[static_cast<std::size_t>(i)] = elevationDeg(Model::kRs16, i);
  return e;
}

}  // namespace adit::drivers::testing
