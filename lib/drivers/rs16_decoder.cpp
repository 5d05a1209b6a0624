#include "drivers/rs16_decoder.hpp"

#include "drivers/packet_bytes.hpp"

#include <algorithm>

namespace adit::drivers {
namespace {

constexpr int kBlocks = 12;
constexpr std::size_t kBlockBytes = 100;
constexpr double kMaxBlockGapCentiDeg = 1000.0;  // see vlp16_decoder.cpp

// Days from 1970-01-01 to y-m-d (civil calendar; month 1..12), by counting from March-based eras.
std::int64_t daysFromCivil(int y, int m, int d) {
  y -= m <= 2 ? 1 : 0;
  const int era = (y >= 0 ? y : y - 399) / 400;
  const int yoe = y - era * 400;                                   // [0, 399]
  const int doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;  // [0, 365]
  const int doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;           // [0, 146096]
  return static_cast<std::int64_t>(era) * 146097 + doe - 719468;
}

// The header's date and time; false if a field is out of range.
bool headerTime(const std::uint8_t* h, std::int64_t& utc_us) {
  const int year = 2000 + h[20], month = h[21], day = h[22], hour = h[23], minute = h[24], second = h[25];
  const int ms = readBe16(h + 26), us = readBe16(h + 28);
  if (month < 1 || month > 12 || day < 1 || day > 31 || hour > 23 || minute > 59 || second > 60 || ms > 999 ||
      us > 999)
    return false;
  utc_us = utcMicros(year, month, day, hour, minute, second, ms * 1000 + us);
  return true;
}

}  // namespace

std::int64_t utcMicros(int year, int month, int day, int hour, int minute, int second, int micros) {
  const std::int64_t seconds = daysFromCivil(year, month, day) * 86400 + hour * 3600 + minute * 60 + second;
  return seconds * 1000000 + micros;
}

Rs16Decoder::Rs16Decoder(const std::array<double, kBeams>& elevation_deg, bool dual_return)
    : beams_(BeamTable::fromElevationsDeg(elevation_deg)), dual_return_(dual_return) {}

bool parseRs16Difop(const std::uint8_t* data, std::size_t size, Rs16Difop& out) {
  if (data == nullptr || size != kRs16PacketSize || !std::equal(kRs16DifopMagic.begin(), kRs16DifopMagic.end(), data))
    return false;
  out = Rs16Difop{};
  out.dual_return = data[300] == 0;
  constexpr std::size_t kAngles = 1165;
  bool blank_zero = true, blank_ff = true, in_range = true;
  for (int i = 0; i < kBeams; ++i) {
    const std::uint8_t* v = data + kAngles + static_cast<std::size_t>(i) * 3;
    const std::uint32_t millideg = (static_cast<std::uint32_t>(v[0]) << 16) | (static_cast<std::uint32_t>(v[1]) << 8) | v[2];
    blank_zero = blank_zero && millideg == 0;
    blank_ff = blank_ff && millideg == 0xFFFFFF;
    const double deg = millideg * 0.001;
    in_range = in_range && deg <= 25.0;  // the head's field of view is +-15 deg
    out.elevation_deg[static_cast<std::size_t>(i)] = i < 8 ? -deg : deg;
  }
  out.has_angles = !blank_zero && !blank_ff && in_range;
  return true;
}

PacketStatus Rs16Decoder::decode(const std::uint8_t* data, std::size_t size, DecodedPacket& out) const {
  resetPacket(out, SensorClock::kUtcMicros);
  if (data == nullptr || size != kRs16PacketSize) return PacketStatus::kWrongSize;
  if (!std::equal(kRs16Magic.begin(), kRs16Magic.end(), data)) return PacketStatus::kBadMagic;
  std::int64_t stamp = 0;
  const bool stamp_valid = headerTime(data, stamp);
  const std::uint8_t* blocks = data + kRs16HeaderSize;
  std::uint16_t azimuth[kBlocks];
  for (int b = 0; b < kBlocks; ++b) {
    const std::uint8_t* block = blocks + b * kBlockBytes;
    if (block[0] != 0xFF || block[1] != 0xEE) return PacketStatus::kBadBlockFlag;
    azimuth[b] = readBe16(block + 2);
    if (azimuth[b] >= 36000) return PacketStatus::kBadAzimuth;
  }
  out.stamp_us = stamp;
  out.stamp_valid = stamp_valid;
  out.dual_return = dual_return_;
  out.firings.reserve(static_cast<std::size_t>(kBlocks * 2 * kBeams));
  if (dual_return_) decodeDual(blocks, azimuth, out);
  else decodeSingle(blocks, azimuth, out);
  out.duration_ns = out.firings.back().offset_ns;
  return PacketStatus::kOk;
}

void Rs16Decoder::decodeSingle(const std::uint8_t* blocks, const std::uint16_t* azimuth, DecodedPacket& out) const {
  for (int b = 0; b < kBlocks; ++b) {
    const int from = b + 1 < kBlocks ? b : b - 1;
    double gap = wrapAzimuthCentiDeg(static_cast<double>(azimuth[from + 1]) - azimuth[from]);
    if (gap > kMaxBlockGapCentiDeg) gap = 0.0;
    for (int seq = 0; seq < 2; ++seq) {
      for (int laser = 0; laser < kBeams; ++laser) {
        const std::int64_t in_block_ns = seq * kRs16SequenceNs + laser * kRs16FiringNs;
        const double az = wrapAzimuthCentiDeg(azimuth[b] + gap * static_cast<double>(in_block_ns) /
                                                               static_cast<double>(kRs16BlockNs)) * 0.01;
        const std::uint8_t* point = blocks + b * kBlockBytes + 4 + static_cast<std::size_t>(seq * kBeams + laser) * 3;
        const std::uint16_t raw = readBe16(point);
        Firing f;
        f.offset_ns = b * kRs16BlockNs + in_block_ns;
        f.azimuth_deg = static_cast<float>(az);
        f.ring = beams_.ring[laser];
        f.intensity = point[2];
        f.has_return = raw != 0;
        if (f.has_return) f.p = beams_.point(raw * kRs16DistanceUnitM, az, laser);
        out.firings.push_back(f);
      }
    }
  }
}

void Rs16Decoder::decodeDual(const std::uint8_t* blocks, const std::uint16_t* azimuth, DecodedPacket& out) const {
  for (int b = 0; b < kBlocks; ++b) {
    const int from = b + 1 < kBlocks ? b : b - 1;
    double gap = wrapAzimuthCentiDeg(static_cast<double>(azimuth[from + 1]) - azimuth[from]);
    if (gap > kMaxBlockGapCentiDeg) gap = 0.0;
    for (int laser = 0; laser < kBeams; ++laser) {
      const std::int64_t in_block_ns = laser * kRs16FiringNs;
      const double az = wrapAzimuthCentiDeg(azimuth[b] + gap * static_cast<double>(in_block_ns) /
                                                             static_cast<double>(kRs16SequenceNs)) * 0.01;
      std::uint16_t first_raw = 0;
      for (int r = 0; r < 2; ++r) {
        const std::uint8_t* point = blocks + b * kBlockBytes + 4 + static_cast<std::size_t>(r * kBeams + laser) * 3;
        const std::uint16_t raw = readBe16(point);
        if (r == 0) first_raw = raw;
        Firing f;
        f.offset_ns = b * kRs16SequenceNs + in_block_ns;
        f.azimuth_deg = static_cast<float>(az);
        f.ring = beams_.ring[laser];
        f.intensity = point[2];
        f.has_return = raw != 0 && !(r == 1 && raw == first_raw);
        if (f.has_return) f.p = beams_.point(raw * kRs16DistanceUnitM, az, laser);
        out.firings.push_back(f);
      }
    }
  }
}

}  // namespace adit::drivers
