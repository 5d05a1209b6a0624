// A synthetic spinning lidar for the driver tests: writes VLP-16 / RS-16 / VLP-32C / HDL-32E packets byte by
// byte (written from the manuals' packet layouts and tables, independently of lib/drivers) with random ranges
// or those of a given scene, and returns the ground truth of every firing: time, continuous azimuth, laser,
// ring, range, intensity and position.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace adit::drivers::testing {

enum class Model { kVlp16, kRs16, kVlp32c, kHdl32e };

int beamsOf(Model model);

struct TruthFiring {
  std::int64_t t_ns = 0;      // since the first firing of packet 0 (exact; sensor stamps are whole us)
  std::int64_t offset_ns = 0; // since the first firing of its packet
  double azimuth_deg = 0.0;   // the head's, [0, 360) (a VLP-32C beam points azimuthOffsetDeg away from it)
  int laser = 0;
  int ring = 0;
  double range_m = 0.0;       // 0 = no return
  int intensity = 0;
  bool has_return = false;    // false also for a dual-return echo equal to the first one
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

struct SyntheticLidar {
  Model model = Model::kVlp16;
  int az0_centideg = 1234;    // azimuth of block 0 of packet 0
  int gap_centideg = 40;      // azimuth advance per firing block (0.40 deg: ~10 Hz)
  std::int64_t stamp0_us = 0; // sensor stamp of packet 0 (VLP-16: us past the hour; RS-16: UTC us)
  bool dual = false;          // dual-return packets (Velodyne: block pairs; RS-16: both echoes in one block)
  double no_return_fraction = 0.05;
  std::uint64_t seed = 1;
  // The scene: range (m) along a beam's unit direction (0 = no return) for the first echo; random if empty.
  std::function<double(const Eigen::Vector3d&)> scene;

  // Packet k of the stream; appends its firings (in packet order) to *truth if given.
  std::vector<std::uint8_t> packet(int k, std::vector<TruthFiring>* truth = nullptr) const;
  std::int64_t blockNs() const;          // time between firing blocks (groups in dual mode)
  int groupsPerPacket() const;           // 12, or 6 in dual mode
  std::int64_t packetNs() const { return blockNs() * groupsPerPacket(); }
  std::int64_t lastFiringNs() const;     // offset of a packet's last firing
  double rotationNs() const { return 36000.0 / gap_centideg * static_cast<double>(blockNs()); }
  std::int64_t stampUs(int k) const;     // sensor stamp of packet k
};

// Nominal elevation (deg), horizontal offset from the head's azimuth (deg, clockwise; VLP-32C only) and ring
// (rank of elevation) of a laser id, from the manuals' tables.
double elevationDeg(Model model, int laser);
double azimuthOffsetDeg(Model model, int laser);
int ringOf(Model model, int laser);

// An RS-16 DIFOP packet: return mode byte 300 (0 dual, 1 strongest), vertical angles at 1165 (3 bytes each,
// 0.001 deg, channels 0..7 negative), per the RS-LiDAR-16 user guide.
std::vector<std::uint8_t> rs16DifopPacket(bool dual, const std::array<double, 16>& elevation_deg);
// The RS-16's nominal elevations by laser id.
std::array<double, 16> nominalRs16Elevations();

// Fixed RS-16 packet date: 2024-03-15 10:20:30.000000 UTC.
constexpr std::int64_t kRs16TestEpochUs = 1710498030LL * 1000000;

}  // namespace adit::drivers::testing
