// What a packet decoder produces: the laser firings of one UDP packet, in firing-time order, as points in
// the lidar frame with their time offset inside the packet. Shared by the VLP-16 and RS-16 decoders and
// consumed by the packet clock and the sweep assembler.
//
// Lidar frame (as the ROS drivers and the rest of adit use it): x forward (the sensor's azimuth 0),
// y left, z up. Both heads spin clockwise seen from above, so the sensor azimuth grows clockwise:
// x = r cos(elev) cos(az), y = -r cos(elev) sin(az), z = r sin(elev).
#pragma once

#include "msg/firing_table.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace adit::drivers {

constexpr int kBeams = 16;

// Why a packet was rejected (kOk: decoded).
enum class PacketStatus {
  kOk,
  kWrongSize,         // not the model's packet size
  kBadMagic,          // RS-16 header does not start with 55 AA 05 0A 5A A5 50 A0
  kBadBlockFlag,      // a data block does not start with FF EE
  kBadAzimuth,        // a block azimuth >= 360.00 deg
  kBadTimestamp,      // RS-16 header date/time out of range while the sensor clock is used
  kUnknownProduct,    // VLP-16 factory byte is not 0x22 (VLP-16) or 0x00 (firmware before 3.0.29)
  kUnknownReturnMode  // VLP-16 factory byte is not 0x37 / 0x38 / 0x39 (or 0x00)
};
// Counter name for Health, e.g. "wrong_size".
const char* counterName(PacketStatus status);

// How the sensor's own packet stamp counts.
enum class SensorClock {
  kMicrosPastHour,  // Velodyne: 0 .. 3,599,999,999 us past the (UTC or power-on) hour, wraps every hour
  kUtcMicros,       // RoboSense: absolute UTC time in us since 1970 (from the header's date and time)
};

struct Firing {
  std::int64_t offset_ns = 0;  // firing time after the packet's first firing (the packet stamp)
  float azimuth_deg = 0.0f;    // head azimuth at the firing [0, 360), clockwise from +x (a VLP-32C beam's
                               // horizontal offset moves its point, not this)
  Eigen::Vector3f p = Eigen::Vector3f::Zero();  // metres, lidar frame; zero when there is no return
  float intensity = 0.0f;      // reflectivity / intensity byte, 0..255
  std::uint16_t ring = 0;      // beam index by elevation, 0 = lowest
  bool has_return = false;     // false: distance 0 (no echo) or a duplicate second echo; not a point
};

struct DecodedPacket {
  std::int64_t stamp_us = 0;  // sensor clock at the packet's first firing
  bool stamp_valid = true;    // false: RS-16 header date/time out of range (usable only on host time)
  SensorClock clock = SensorClock::kMicrosPastHour;
  std::int64_t duration_ns = 0;  // offset of the packet's last firing
  bool dual_return = false;
  std::vector<Firing> firings;   // non-decreasing offset_ns
};

// Beam geometry: elevation of each laser id (its slot in a firing sequence) and its ring.
struct BeamTable {
  std::array<float, kBeams> cos_elevation{};
  std::array<float, kBeams> sin_elevation{};
  std::array<std::uint16_t, kBeams> ring{};  // rank of the laser's elevation, ties by laser id

  // Throws std::invalid_argument unless every angle is finite and within [-90, 90] degrees.
  static BeamTable fromElevationsDeg(const std::array<double, kBeams>& elevation_deg);
  // Lidar-frame point of a return at `range_m` from laser `laser` at sensor azimuth `azimuth_deg`.
  Eigen::Vector3f point(double range_m, double azimuth_deg, int laser) const;
};

// The head's firing table for the compact sweep encoder: ring of laser slot k fires k * firing_ns after its
// sequence's first firing (VLP-16: 2304 ns, RS-16: 2800 ns).
msg::FiringTable firingTable(const BeamTable& beams, std::int64_t firing_ns);

// Empties `packet` for the next decode, keeping its firing buffer (no allocation per packet).
void resetPacket(DecodedPacket& packet, SensorClock clock);

// Wraps an azimuth in hundredths of a degree into [0, 36000).
double wrapAzimuthCentiDeg(double centi_deg);

}  // namespace adit::drivers
