#include "drivers/vlp16_encoder.hpp"

#include "drivers/vlp16_decoder.hpp"

#include <cmath>

namespace adit::drivers {
namespace {

void putLe16(std::uint8_t* p, unsigned v) {
  p[0] = static_cast<std::uint8_t>(v & 0xFF);
  p[1] = static_cast<std::uint8_t>((v >> 8) & 0xFF);
}

unsigned rangeCount(float range_m) {
  if (!std::isfinite(range_m) || range_m <= 0.0f) return 0;
  const long count = std::lround(static_cast<double>(range_m) / kVlp16DistanceUnitM);
  return count > 65535 ? 0 : static_cast<unsigned>(count);
}

}  // namespace

bool Vlp16PacketEncoder::add(const FiringSequence& sequence, std::vector<std::uint8_t>& packet,
                             std::int64_t& first_firing_ns) {
  pending_.push_back(sequence);
  constexpr std::size_t kSequences = 24;
  if (pending_.size() < kSequences) return false;
  packet.assign(kVlp16PacketSize, 0);
  for (std::size_t b = 0; b < 12; ++b) {
    std::uint8_t* block = packet.data() + b * 100;
    block[0] = 0xFF;
    block[1] = 0xEE;
    const double centi = wrapAzimuthCentiDeg(std::round(pending_[2 * b].azimuth_deg * 100.0));
    putLe16(block + 2, static_cast<unsigned>(centi) % 36000);
    for (std::size_t s = 0; s < 2; ++s) {
      const FiringSequence& q = pending_[2 * b + s];
      for (std::size_t laser = 0; laser < kBeams; ++laser) {
        std::uint8_t* point = block + 4 + (s * kBeams + laser) * 3;
        putLe16(point, rangeCount(q.range_m[laser]));
        point[2] = q.intensity[laser];
      }
    }
  }
  first_firing_ns = pending_.front().time_ns;
  // Microseconds past the hour (the sensor's clock synchronised to UTC).
  const std::int64_t us = first_firing_ns / 1000;
  const auto stamp = static_cast<std::uint32_t>(((us % 3600000000LL) + 3600000000LL) % 3600000000LL);
  for (int i = 0; i < 4; ++i) packet[1200 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>((stamp >> (8 * i)) & 0xFF);
  packet[1204] = kVlp16Strongest;
  packet[1205] = kVlp16ProductId;
  pending_.clear();
  return true;
}

}  // namespace adit::drivers
