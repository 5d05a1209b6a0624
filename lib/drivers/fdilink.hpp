// The WHEELTEC N100's serial protocol (FDILink, by FDISYSTEMS): a byte stream of frames
//
//   0xFC  type  length  serial  CRC8  CRC16-hi  CRC16-lo  payload[length]  0xFD
//
// CRC8 (CRC-8/MAXIM: reflected polynomial 0x8C, initial 0) covers the first four bytes, CRC16
// (CRC-16/XMODEM: polynomial 0x1021, initial 0, high byte first) the payload; a frame of length 0 ends after
// its CRC8. `serial` counts frames modulo 256. Payloads are little-endian: packet 0x40 (IMU) is gyro xyz
// (rad/s), accelerometer xyz (m/s^2), magnetometer xyz, IMU temperature, pressure, pressure temperature
// (float32 each) and a timestamp (int64, microseconds of the device clock) = 56 bytes; packet 0x41 (AHRS) is
// roll/pitch/heading rates and angles (rad) and a quaternion q1..q4 (w, x, y, z) (float32 each) and the same
// timestamp = 48 bytes. Source: FDILink's frame layout, flag bytes and CRC tables (FDILink.h, CRC_Table.c of
// the vendor's "FDILink" library, frame offsets FDILink_Frame_Start..End) and its packet structures
// FDILink_IMUData_Packet_t / FDILink_AHRSData_Packet_t (fdilink_decode.h, packet ids 0x40 / 0x41).
//
// The parser takes bytes as they arrive (any split), finds frames, and resynchronises after noise: a byte
// that does not start a valid frame is skipped and counted, never fatal.
#pragma once

#include "core/types.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace adit::drivers {

std::uint8_t fdiCrc8(const std::uint8_t* data, std::size_t size);
std::uint16_t fdiCrc16(const std::uint8_t* data, std::size_t size);

struct FdiFrame {
  std::uint8_t type = 0;
  std::uint8_t serial = 0;
  std::vector<std::uint8_t> payload;
};

// A frame as the device sends it (for tests, the fuzzer's seeds and the simulator of a device).
std::vector<std::uint8_t> encodeFdiFrame(std::uint8_t type, std::uint8_t serial, const std::vector<std::uint8_t>& payload);

class FdiLinkParser {
 public:
  // Feeds bytes; `on_frame` is called for every complete frame whose checks pass, in order.
  void push(const std::uint8_t* data, std::size_t size, const std::function<void(const FdiFrame&)>& on_frame);
  // "crc8_error", "crc16_error", "bad_tail", "skipped_bytes", "lost_frames" (gaps in `serial`), "frames".
  const std::map<std::string, std::int64_t>& counters() const { return counters_; }

 private:
  // Tries to take one frame from the buffer's start: +n = consumed a frame of n bytes, 0 = need more bytes,
  // -1 = the start is not a frame (skip a byte).
  int takeFrame(const std::function<void(const FdiFrame&)>& on_frame);

  std::vector<std::uint8_t> buffer_;
  std::optional<std::uint8_t> last_serial_;
  std::map<std::string, std::int64_t> counters_;
};

// Packet ids and sizes (fdilink_decode.h).
constexpr std::uint8_t kFdiImuPacket = 0x40;
constexpr std::uint8_t kFdiAhrsPacket = 0x41;
constexpr std::size_t kFdiImuPayloadBytes = 56;
constexpr std::size_t kFdiAhrsPayloadBytes = 48;

struct FdiImu {
  std::int64_t device_us = 0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
};
struct FdiAhrs {
  std::int64_t device_us = 0;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

// nullopt when the payload has the wrong size or a non-finite value (a corrupt frame that passed the CRC).
std::optional<FdiImu> decodeFdiImu(const std::vector<std::uint8_t>& payload);
std::optional<FdiAhrs> decodeFdiAhrs(const std::vector<std::uint8_t>& payload);

// Payloads as the N100 writes them (tests, seeds).
std::vector<std::uint8_t> encodeFdiImu(const FdiImu& imu);
std::vector<std::uint8_t> encodeFdiAhrs(const FdiAhrs& ahrs);

}  // namespace adit::drivers
