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

// VLP-32C User Manual (63-9325) table 9-2, by laser id: elevation and horizontal offset delta.
constexpr double kVlp32cElevation[32] = {-25,    -1,     -1.667, -15.639, -11.31, 0,     -0.667, -8.843,
                                         -7.254, 0.333,  -0.333, -6.148,  -5.333, 1.333, 0.667,  -4,
                                         -4.667, 1.667,  1,      -3.667,  -3.333, 3.333, 2.333,  -2.667,
                                         -3,     7,      4.667,  -2.333,  -2,     15,    10.333, -1.333};
constexpr double kVlp32cDelta[32] = {1.4, -4.2, 1.4, -1.4, 1.4, -1.4, 4.2, -1.4, 1.4, -4.2, 1.4, -1.4, 4.2, -1.4, 4.2, -1.4,
                                     1.4, -4.2, 1.4, -4.2, 4.2, -1.4, 1.4, -1.4, 1.4, -1.4, 1.4, -4.2, 4.2, -1.4, 1.4, -1.4};
// HDL-32E User's Manual (63-9113) vertical angles: even ids the lower half, odd ids the upper half.
constexpr double kHdl32eLow[16] = {-30.67, -29.33, -28.00, -26.67, -25.33, -24.00, -22.67, -21.33,
                                   -20.00, -18.67, -17.33, -16.00, -14.67, -13.33, -12.00, -10.67};
constexpr double kHdl32eHigh[16] = {-9.33, -8.00, -6.67, -5.33, -4.00, -2.67, -1.33, 0.00,
                                    1.33,  2.67,  4.00,  5.33,  6.67,  8.00,  9.33,  10.67};

int beamsOf(Model model) { return model == Model::kVlp32c || model == Model::kHdl32e ? 32 : 16; }

double elevationDeg(Model model, int laser) {
  switch (model) {
    case Model::kVlp16: return laser % 2 == 0 ? -15.0 + laser : static_cast<double>(laser);
    case Model::kRs16: return laser < 8 ? -15.0 + 2 * laser : 15.0 - 2 * (laser - 8);
    case Model::kVlp32c: return kVlp32cElevation[laser];
    case Model::kHdl32e: return laser % 2 == 0 ? kHdl32eLow[laser / 2] : kHdl32eHigh[laser / 2];
  }
  return 0.0;
}

double azimuthOffsetDeg(Model model, int laser) { return model == Model::kVlp32c ? kVlp32cDelta[laser] : 0.0; }

int ringOf(Model model, int laser) {
  int rank = 0;  // lasers below it (ties: the lower id first)
  for (int other = 0; other < beamsOf(model); ++other) {
    const double a = elevationDeg(model, other), b = elevationDeg(model, laser);
    if (a < b || (a == b && other < laser)) ++rank;
  }
  return rank;
}

namespace {

// Per head: distance unit, time between firings, lasers fired together, and the firing sequences in a
// (single-return) block.
struct Timing {
  double unit_m;
  std::int64_t sequence_ns, firing_ns;
  int lasers_per_firing, sequences_per_block;
  std::uint8_t product;
};

Timing timingOf(Model model) {
  switch (model) {
    case Model::kVlp16: return {0.002, 55296, 2304, 1, 2, 0x22};
    case Model::kRs16: return {0.005, 55500, 2800, 1, 2, 0};
    case Model::kVlp32c: return {0.004, 55296, 2304, 2, 1, 0x28};
    case Model::kHdl32e: return {0.002, 46080, 1152, 1, 1, 0x21};
  }
  return {};
}

}  // namespace

// RS-16 dual return: one sequence per block (both echoes in it), so a block is one sequence long.
std::int64_t SyntheticLidar::blockNs() const {
  const Timing t = timingOf(model);
  return model == Model::kRs16 && dual ? t.sequence_ns : t.sequence_ns * t.sequences_per_block;
}
int SyntheticLidar::groupsPerPacket() const { return dual && model != Model::kRs16 ? 6 : 12; }
std::int64_t SyntheticLidar::lastFiringNs() const {
  const Timing t = timingOf(model);
  const int firings = beamsOf(model) / t.lasers_per_firing;
  if (model == Model::kRs16) return packetNs() - blockNs() + (dual ? 0 : 55500) + (firings - 1) * t.firing_ns;
  return packetNs() - t.sequence_ns + (firings - 1) * t.firing_ns;
}

std::int64_t SyntheticLidar::stampUs(int k) const {
  const std::int64_t us = stamp0_us + (static_cast<std::int64_t>(k) * packetNs()) / 1000;  // whole us, truncated
  return model == Model::kRs16 ? us : us % 3600000000LL;
}

std::vector<std::uint8_t> SyntheticLidar::packet(int k, std::vector<TruthFiring>* truth) const {
  const bool vlp = model != Model::kRs16;  // the Velodyne family
  const Timing timing = timingOf(model);
  const std::size_t header = vlp ? 0 : 42;
  std::vector<std::uint8_t> bytes(vlp ? 1206 : 1248, 0);
  const double unit = timing.unit_m;
  const int returns = dual ? 2 : 1, beams = beamsOf(model);
  // Velodyne dual: block pairs (one per echo) of the single-return block's sequences; RS-16 dual: one block
  // of one sequence whose slots 0..15 hold the first echo and 16..31 the second.
  const bool rs_dual = !vlp && dual;
  const int blocks_per_group = rs_dual ? 1 : returns, sequences = rs_dual ? 1 : timing.sequences_per_block;
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
      for (int laser = 0; laser < beams; ++laser) {
        const std::int64_t in_block = s * timing.sequence_ns + (laser / timing.lasers_per_firing) * timing.firing_ns;
        const double az = az0_centideg + gap_centideg * (static_cast<double>(n) + static_cast<double>(in_block) /
                                                                                     static_cast<double>(blockNs()));
        const double e = elevationDeg(model, laser) * M_PI / 180.0,
                     a = (az / 100.0 + azimuthOffsetDeg(model, laser)) * M_PI / 180.0;
        const Eigen::Vector3d direction(std::cos(e) * std::cos(a), -std::cos(e) * std::sin(a), std::sin(e));
        unsigned first_raw = 0;
        for (int r = 0; r < returns; ++r) {
          const std::uint64_t h = mix(seed ^ mix(static_cast<std::uint64_t>(n * 64 + s * beams + laser) * 4 + r));
          const double u = static_cast<double>(h >> 11) / 9007199254740992.0;  // [0, 1)
          const double range = scene && r == 0 ? scene(direction) : 0.5 + 99.5 * u;
          unsigned raw = static_cast<unsigned>(std::lround(range / unit));
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
          f.azimuth_deg = std::fmod(az, 36000.0) / 100.0;
          f.laser = laser;
          f.ring = ringOf(model, laser);
          f.range_m = raw * unit;
          f.intensity = intensity;
          f.has_return = raw != 0 && !(r == 1 && raw == first_raw);
          if (f.has_return) f.p = f.range_m * direction;
          truth->push_back(f);
        }
      }
    }
  }
  const std::int64_t stamp = stampUs(k);
  if (vlp) {
    for (int i = 0; i < 4; ++i) bytes[1200 + i] = static_cast<std::uint8_t>((stamp >> (8 * i)) & 0xFF);
    bytes[1204] = dual ? 0x39 : 0x37;
    bytes[1205] = timing.product;
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
