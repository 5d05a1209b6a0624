// The one encoder and decoder of compact sweeps (adit::lidar_scan_t, see its .lcm for the layouts). Every
// writer of LIDAR_POINTS (simulator, importers, live drivers) encodes through encodeSweep(); every reader goes
// through decodeSweep() or SweepMessage, which also reads the full-float point_cloud_t of older logs.
#pragma once

#include "msg/validate.hpp"
#include "msg/wire_check.hpp"

#include "core/types.hpp"
#include "msg/firing_table.hpp"

#include <adit/lidar_scan_t.hpp>
#include <adit/point_cloud_t.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace adit::msg {

constexpr std::int16_t kSweepFormatVersion = 1;

// Metres per range count: the sensor's own range resolution (VLP-16 packets: 2 mm; finer than RS-16's 5 mm
// and KITTI's float ranges need). 65535 counts reach 131 m; sweeps with longer ranges get a coarser scale.
constexpr float kRangeScale = 0.002f;

// Encodes `scan` in the firing-grid layout when `table` is given, the scan has rings and times, and every
// point decodes back within the grid's resolution; otherwise (no table, a point off the grid) in the
// per-point layout. Never throws; non-finite points are left out.
adit::lidar_scan_t encodeSweep(const LidarScan& scan, const FiringTable* table);

// How far a decoded point may lie from the original at range `range_m` (m): half a range count plus the
// angular quantisation (1e-4 rad, below the 0.01 deg azimuth resolution of VLP-16 / RS-16 packets).
double sweepTolerance(double range_m, float range_scale);

// Decodes a compact sweep. Returns "" on success, else why the message does not fit its sensor profile or
// format (counts, ranges, firing table, version); `scan` is then unspecified.
std::string decodeSweep(const adit::lidar_scan_t& m, LidarScan& scan);
// Beams of a known sensor profile ("vlp16", "rs16": 16; "vlp32c", "hdl32e": 32; "hdl64": 64), 0 for another name.
int profileBeams(const std::string& sensor);

// Either sweep message from its bytes, for a node's LIDAR_POINTS input (Node::subscribe decodes through it):
// lidar_scan_t (compact) or point_cloud_t (full floats, older logs), told apart by fingerprint.
struct SweepMessage {
  adit::header_t header;
  LidarScan scan;
  bool compact = false;
  std::string error;             // non-empty: a compact sweep that does not fit its profile (skip it)
  bool unknown_version = false;  // the error is an unknown format_version

  // LCM's decode contract: bytes used, or -1 if the bytes are neither type.
  int decode(const void* buf, int offset, int maxlen);
};

// The node's input checks for LIDAR_POINTS (runtime/node.hpp): the wire layout of whichever sweep type the
// bytes' fingerprint names, and the values that survive decoding (the header; the sweep's duration). Raw
// non-finite points are left to preprocessing, which removes and counts them.
template <>
inline WireCheck checkWire<SweepMessage>(const std::uint8_t* data, std::size_t size, const WireLimits& limits) {
  const int full = wire::TypeIndex<adit::point_cloud_t>::value;
  std::uint64_t hash = 0;
  for (std::size_t i = 0; i < 8 && i < size; ++i) hash = (hash << 8) | data[i];
  if (size >= 8 && hash == wireHash(full)) return checkWire(full, data, size, limits);
  return checkWire<adit::lidar_scan_t>(data, size, limits);
}
Validation validate(const SweepMessage& m, const InputLimits& limits);

}  // namespace adit::msg
