#include "drivers/vlp16_decoder.hpp"

#include "drivers/packet_bytes.hpp"

#include <algorithm>

namespace adit::drivers {
namespace {

constexpr int kBlocks = kVelodyneBlocks;
constexpr std::size_t kBlockBytes = 100;
// Azimuth advance between blocks above this (10 deg) is not rotation (the head turns < 1 deg per block at
// 1200 rpm): such a packet straddles a glitch, and its firings keep the block azimuth.
constexpr double kMaxBlockGapCentiDeg = 1000.0;

double forwardGap(std::uint16_t from, std::uint16_t to) {
  return wrapAzimuthCentiDeg(static_cast<double>(to) - static_cast<double>(from));
}

}  // namespace

PacketStatus readVelodyneFrame(const std::uint8_t* data, std::size_t size, std::uint8_t product_id,
                               const std::vector<std::uint8_t>& accept_products,
                               std::uint16_t (&azimuth)[kVelodyneBlocks], DecodedPacket& out) {
  resetPacket(out, SensorClock::kMicrosPastHour);
  if (data == nullptr || size != kVlp16PacketSize) return PacketStatus::kWrongSize;
  const std::uint8_t mode = data[1204], product = data[1205];
  if (product != product_id && product != 0 &&
      std::find(accept_products.begin(), accept_products.end(), product) == accept_products.end())
    return PacketStatus::kUnknownProduct;
  if (mode != kVlp16Strongest && mode != kVlp16Last && mode != kVlp16Dual && mode != 0)
    return PacketStatus::kUnknownReturnMode;
  for (int b = 0; b < kVelodyneBlocks; ++b) {
    const std::uint8_t* block = data + b * kBlockBytes;
    if (block[0] != 0xFF || block[1] != 0xEE) return PacketStatus::kBadBlockFlag;
    azimuth[b] = readLe16(block + 2);
    if (azimuth[b] >= 36000) return PacketStatus::kBadAzimuth;
  }
  out.stamp_us = readLe32(data + 1200);
  out.dual_return = mode == kVlp16Dual;
  return PacketStatus::kOk;
}

Vlp16Decoder::Vlp16Decoder(const std::array<double, kBeams>& elevation_deg, std::vector<std::uint8_t> accept_products)
    : beams_(BeamTable::fromElevationsDeg(elevation_deg)), accept_products_(std::move(accept_products)) {}

PacketStatus Vlp16Decoder::decode(const std::uint8_t* data, std::size_t size, DecodedPacket& out) const {
  std::uint16_t azimuth[kBlocks];
  const PacketStatus status = readVelodyneFrame(data, size, kVlp16ProductId, accept_products_, azimuth, out);
  if (status != PacketStatus::kOk) return status;

  // Dual return: block pairs (2k: last echo, 2k+1: strongest or second strongest) share their firings.
  const int returns = out.dual_return ? 2 : 1;
  const int groups = kBlocks / returns;
  out.firings.reserve(static_cast<std::size_t>(kBlocks * 2 * kBeams));
  for (int g = 0; g < groups; ++g) {
    const int b = g * returns;
    double gap = b + returns < kBlocks ? forwardGap(azimuth[b], azimuth[b + returns])
                                       : forwardGap(azimuth[b - returns], azimuth[b]);
    if (gap > kMaxBlockGapCentiDeg) gap = 0.0;
    for (int seq = 0; seq < 2; ++seq) {
      for (int laser = 0; laser < kBeams; ++laser) {
        const std::int64_t in_block_ns = seq * kVlp16SequenceNs + laser * kVlp16FiringNs;
        const double az = wrapAzimuthCentiDeg(azimuth[b] + gap * static_cast<double>(in_block_ns) /
                                                               static_cast<double>(kVlp16BlockNs)) * 0.01;
        const std::size_t slot = static_cast<std::size_t>(seq * kBeams + laser);
        std::uint16_t first_raw = 0;
        for (int r = 0; r < returns; ++r) {
          const std::uint8_t* point = data + (b + r) * kBlockBytes + 4 + slot * 3;
          const std::uint16_t raw = readLe16(point);
          if (r == 0) first_raw = raw;
          Firing f;
          f.offset_ns = g * kVlp16BlockNs + in_block_ns;
          f.azimuth_deg = static_cast<float>(az);
          f.ring = beams_.ring[laser];
          f.intensity = point[2];
          // The second echo repeats the first when the strongest echo is also the last one.
          f.has_return = raw != 0 && !(r == 1 && raw == first_raw);
          if (f.has_return) f.p = beams_.point(raw * kVlp16DistanceUnitM, az, laser);
          out.firings.push_back(f);
        }
      }
    }
  }
  out.duration_ns = out.firings.back().offset_ns;
  return PacketStatus::kOk;
}

}  // namespace adit::drivers
