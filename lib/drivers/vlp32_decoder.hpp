// The 32-beam members of the Velodyne packet family: VLP-32C and HDL-32E data packets (UDP port 2368, 1206
// bytes, the VLP-16's framing: 12 blocks of flag FF EE, azimuth uint16 LE in 0.01 deg and 32 data points of
// distance uint16 LE + reflectivity; uint32 LE stamp in us past the hour at byte 1200; return mode and product
// id at 1204 / 1205). Each block holds ONE firing sequence of all 32 lasers (dual return: block pairs of the
// same firings, as the VLP-16's).
//  - VLP-32C (VLP-32C User Manual 63-9325 Rev C, section 9.4 and tables 9-2, 9-5, 9-6): lasers fire in pairs,
//    2k and 2k+1 together, 2.304 us apart; a sequence (16 pairs + recharge) takes 55.296 us; distances count
//    4 mm; each laser has its elevation and a horizontal offset delta of +-1.4 or +-4.2 deg added to the
//    block's (interpolated) azimuth; product id 0x28.
//  - HDL-32E (HDL-32E User's Manual 63-9113, "laser firing sequence" and the vertical angle table): lasers fire
//    one after another 1.152 us apart, 46.08 us per sequence; distances count 2 mm; elevations -30.67 to
//    +10.67 deg in 1.33 deg steps, interleaved low/high by laser id; all lasers in one column (no offset);
//    product id 0x21.
// Per-laser calibration beyond these published tables (each unit's db.xml) is not applied.
#pragma once

#include "drivers/firing.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace adit::drivers {

constexpr int kBeams32 = 32;

enum class Velodyne32 { kVlp32c, kHdl32e };

struct Laser32 {
  double elevation_deg = 0.0;
  double azimuth_offset_deg = 0.0;  // delta, added to the sensor azimuth (clockwise)
  std::int64_t offset_ns = 0;       // firing time after the sequence's first firing
};

struct Velodyne32Spec {
  std::array<Laser32, kBeams32> lasers{};
  std::int64_t sequence_ns = 0;   // one block
  double distance_unit_m = 0.0;
  std::uint8_t product_id = 0;
};
const Velodyne32Spec& velodyne32Spec(Velodyne32 model);

// The head's firing table for the compact sweep encoder (ring = rank of the laser's elevation).
msg::FiringTable firingTable32(Velodyne32 model);

class Vlp32Decoder {
 public:
  explicit Vlp32Decoder(Velodyne32 model, std::vector<std::uint8_t> accept_products = {});
  PacketStatus decode(const std::uint8_t* data, std::size_t size, DecodedPacket& out) const;

 private:
  const Velodyne32Spec& spec_;
  std::vector<std::uint8_t> accept_products_;
  std::array<float, kBeams32> cos_el_{}, sin_el_{};
  std::array<std::uint16_t, kBeams32> ring_{};
};

}  // namespace adit::drivers
