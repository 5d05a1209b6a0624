// Writes VLP-16 data packets (the layout Vlp16Decoder reads, see vlp16_decoder.hpp) from firing sequences:
// two sequences per block, twelve blocks per packet, strongest-return mode, product id VLP-16, the stamp in
// microseconds past the hour of the packet's first firing. For `adit sim --pcap` (a simulated run as the
// packets a VLP-16 would have sent) and for tests.
#pragma once

#include "drivers/firing.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace adit::drivers {

struct FiringSequence {
  std::int64_t time_ns = 0;   // first firing of the sequence (ns since 1970)
  double azimuth_deg = 0.0;   // sensor azimuth (clockwise) of its first firing
  std::array<float, kBeams> range_m{};          // by laser id (slot order); 0 = no return
  std::array<std::uint8_t, kBeams> intensity{};
};

class Vlp16PacketEncoder {
 public:
  // Adds a sequence; when it completes a packet (24 sequences), returns true with the packet's 1206 bytes and
  // its first firing's time. Ranges beyond the format's 131 m, or not finite, are written as no return.
  bool add(const FiringSequence& sequence, std::vector<std::uint8_t>& packet, std::int64_t& first_firing_ns);
  // Sequences waiting for a packet (fewer than 24): a stream's tail that fills no packet is not written.
  std::size_t pending() const { return pending_.size(); }

 private:
  std::vector<FiringSequence> pending_;
};

// The offset of a VLP-16 packet's last firing after its first (11 blocks + 1 sequence + 15 lasers).
constexpr std::int64_t kVlp16PacketDurationNs = 11 * 2 * 55296 + 55296 + 15 * 2304;

}  // namespace adit::drivers
