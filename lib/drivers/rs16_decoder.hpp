// RoboSense RS-LiDAR-16 MSOP packets (UDP port 6699, 1248 bytes), single-return mode:
//   42-byte header: magic 55 AA 05 0A 5A A5 50 A0, 12 reserved bytes, then the UTC time of the packet's
//   first firing (year-2000, month, day, hour, minute, second, millisecond uint16 BE, microsecond
//   uint16 BE), then lidar type, temperature, reserved;
//   12 blocks of 100 bytes: flag FF EE, azimuth uint16 BE in 0.01 deg, 32 channel slots = 2 firing
//   sequences x 16 lasers, each distance uint16 BE in 0.5 cm units (0 = no return) + intensity byte;
//   a 6-byte tail.
// Timing (RoboSense's published RS-16 firing table): lasers fire every 2.8 us, the second sequence of a block
// starts 55.5 us after the first, blocks are 111 us apart. Firing azimuths are interpolated inside a block
// like the VLP-16's. Channels 0..7 look down (-15..-1 deg), 8..15 up in reverse (15..1 deg); the per-unit
// calibration the sensor sends in its DIFOP packets can be given as a 16-angle table instead.
// Dual-return mode is not decoded: its block layout is announced only in DIFOP packets (not read here).
#pragma once

#include "drivers/firing.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace adit::drivers {

constexpr std::size_t kRs16PacketSize = 1248;
constexpr std::size_t kRs16HeaderSize = 42;
constexpr std::uint16_t kRs16DefaultPort = 6699;
constexpr std::array<std::uint8_t, 8> kRs16Magic = {0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0};
constexpr std::int64_t kRs16FiringNs = 2800;
constexpr std::int64_t kRs16SequenceNs = 55500;
constexpr std::int64_t kRs16BlockNs = 2 * kRs16SequenceNs;
constexpr double kRs16DistanceUnitM = 0.005;
constexpr std::array<double, kBeams> kRs16ElevationsDeg = {-15, -13, -11, -9, -7, -5, -3, -1,
                                                            15,  13,  11,  9,  7,  5,  3,  1};

class Rs16Decoder {
 public:
  explicit Rs16Decoder(const std::array<double, kBeams>& elevation_deg = kRs16ElevationsDeg);

  // Decodes one UDP payload into `out` (cleared first). Anything but kOk leaves `out` empty. A header time
  // out of range (a sensor that never had its clock set) still decodes, with out.stamp_valid false.
  PacketStatus decode(const std::uint8_t* data, std::size_t size, DecodedPacket& out) const;

 private:
  BeamTable beams_;
};

// Microseconds since 1970-01-01 UTC of a proleptic Gregorian date and time (no leap seconds).
std::int64_t utcMicros(int year, int month, int day, int hour, int minute, int second, int micros);

}  // namespace adit::drivers
