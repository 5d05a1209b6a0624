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
// Dual-return mode (announced only in the DIFOP packet's return-mode byte, see Rs16Difop): each block holds
// ONE firing sequence, slots 0..15 the first echo and 16..31 the second of the same 16 firings, and blocks
// are one sequence (55.5 us) apart (RS-LiDAR-16 user guide, dual-return data block; as RoboSense's rs_driver
// reads it). A second echo equal to the first is not a second point.
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
  explicit Rs16Decoder(const std::array<double, kBeams>& elevation_deg = kRs16ElevationsDeg, bool dual_return = false);

  // Decodes one UDP payload into `out` (cleared first). Anything but kOk leaves `out` empty. A header time
  // out of range (a sensor that never had its clock set) still decodes, with out.stamp_valid false.
  PacketStatus decode(const std::uint8_t* data, std::size_t size, DecodedPacket& out) const;

 private:
  void decodeSingle(const std::uint8_t* blocks, const std::uint16_t* azimuth, DecodedPacket& out) const;
  void decodeDual(const std::uint8_t* blocks, const std::uint16_t* azimuth, DecodedPacket& out) const;

  BeamTable beams_;
  bool dual_return_;
};

// The DIFOP (device information) packet an RS-16 sends once a second to UDP port 7788: 1248 bytes, header
// A5 FF 00 5A 11 11 55 55. Read from it (RS-LiDAR-16 user guide, appendix "DIFOP"; offsets as in RoboSense's
// rs_driver RS16DifopPkt): the return mode at byte 300 (0 dual, 1 strongest, 2 last) and the vertical
// angle calibration at bytes 1165..1212, 16 x 3 bytes big-endian unsigned in 0.001 deg, channels 0..7
// below the horizon (negative), 8..15 above.
constexpr std::uint16_t kRs16DifopPort = 7788;
constexpr std::array<std::uint8_t, 8> kRs16DifopMagic = {0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};
struct Rs16Difop {
  bool dual_return = false;
  bool has_angles = false;  // false: the calibration bytes are blank (all 0 or all FF) or out of range
  std::array<double, kBeams> elevation_deg{};
};
// True if `data` is a DIFOP packet (size and header); `out` then holds what it says.
bool parseRs16Difop(const std::uint8_t* data, std::size_t size, Rs16Difop& out);

// Microseconds since 1970-01-01 UTC of a proleptic Gregorian date and time (no leap seconds).
std::int64_t utcMicros(int year, int month, int day, int hour, int minute, int second, int micros);

}  // namespace adit::drivers
