// Velodyne VLP-16 data packets (UDP port 2368, 1206-byte payload), per the VLP-16 user manual:
//   12 data blocks of 100 bytes: flag FF EE, azimuth uint16 LE in 0.01 deg, then 32 data points =
//   2 firing sequences x 16 lasers, each distance uint16 LE in 2 mm units (0 = no return) + reflectivity;
//   then a uint32 LE timestamp (us past the hour) of the first firing of block 0, and two factory bytes:
//   return mode (0x37 strongest, 0x38 last, 0x39 dual) and product id (0x22 = VLP-16).
// Timing: lasers fire every 2.304 us, a 16-laser sequence takes 55.296 us (with recharge), a block holds
// two sequences (110.592 us). In dual-return mode blocks come in pairs (last, strongest) of the same firings.
// The azimuth of each firing is interpolated between its block's azimuth and the next block's by its time
// inside the block (the manual's "precision azimuth"), so the second sequence sits half a block later.
#pragma once

#include "drivers/firing.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace adit::drivers {

constexpr std::size_t kVlp16PacketSize = 1206;
constexpr std::uint16_t kVlp16DefaultPort = 2368;
constexpr std::int64_t kVlp16FiringNs = 2304;     // between consecutive lasers
constexpr std::int64_t kVlp16SequenceNs = 55296;  // one firing sequence of 16 lasers
constexpr std::int64_t kVlp16BlockNs = 2 * kVlp16SequenceNs;
constexpr double kVlp16DistanceUnitM = 0.002;
constexpr std::uint8_t kVlp16ProductId = 0x22;
constexpr std::uint8_t kVlp16Strongest = 0x37, kVlp16Last = 0x38, kVlp16Dual = 0x39;
// Elevation of laser id 0..15 (slot order in a firing sequence), from the manual: -15, 1, -13, 3, ...
constexpr std::array<double, kBeams> kVlp16ElevationsDeg = {-15, 1, -13, 3, -11, 5, -9, 7,
                                                             -7, 9, -5,  11, -3, 13, -1, 15};

class Vlp16Decoder {
 public:
  // elevation_deg: per laser id; a calibrated unit may differ slightly from the nominal table.
  // accept_products: factory product ids decoded besides 0x22 and 0 (units that announce another product
  // but send VLP-16 packets).
  explicit Vlp16Decoder(const std::array<double, kBeams>& elevation_deg = kVlp16ElevationsDeg,
                        std::vector<std::uint8_t> accept_products = {});

  // Decodes one UDP payload into `out` (cleared first). Anything but kOk leaves `out` empty.
  PacketStatus decode(const std::uint8_t* data, std::size_t size, DecodedPacket& out) const;

 private:
  BeamTable beams_;
  std::vector<std::uint8_t> accept_products_;
};

// The packet family's common frame (VLP-16, VLP-32C, HDL-32E: 12 blocks of FF EE, azimuth, 32 points; stamp and
// factory bytes at the end): checks size, product byte (`product_id`, 0 for old firmware, or one of
// `accept_products`), return mode, block flags and azimuths, fills `azimuth` (centi-degrees) and sets
// out.stamp_us and out.dual_return. kOk, or what is wrong.
constexpr int kVelodyneBlocks = 12;
PacketStatus readVelodyneFrame(const std::uint8_t* data, std::size_t size, std::uint8_t product_id,
                               const std::vector<std::uint8_t>& accept_products,
                               std::uint16_t (&azimuth)[kVelodyneBlocks], DecodedPacket& out);

}  // namespace adit::drivers
