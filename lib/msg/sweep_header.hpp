// The per-sweep fields that the full (point_cloud_t) and the compact (lidar_scan_t) sweep messages share,
// read into a LidarScan without its points. Both types name these fields alike and use point_cloud_t's flags.
#pragma once

#include "core/types.hpp"

#include <adit/point_cloud_t.hpp>

namespace adit::msg {

// point_cloud_t's flag bits of a sweep.
inline std::int32_t sweepFlags(const LidarScan& scan) {
  return (scan.has_ring ? adit::point_cloud_t::FLAG_HAS_RING : 0) |
         (scan.has_time ? adit::point_cloud_t::FLAG_HAS_TIME : 0) |
         (scan.deskewed ? adit::point_cloud_t::FLAG_DESKEWED : 0) |
         (scan.partial ? adit::point_cloud_t::FLAG_PARTIAL : 0);
}
inline void setSweepFlags(std::int32_t flags, LidarScan& scan) {
  scan.has_ring = (flags & adit::point_cloud_t::FLAG_HAS_RING) != 0;
  scan.has_time = (flags & adit::point_cloud_t::FLAG_HAS_TIME) != 0;
  scan.deskewed = (flags & adit::point_cloud_t::FLAG_DESKEWED) != 0;
  scan.partial = (flags & adit::point_cloud_t::FLAG_PARTIAL) != 0;
}

template <class SweepMessage>
LidarScan sweepHeader(const SweepMessage& m) {
  LidarScan s;
  s.utime = m.header.utime;
  s.seq = m.header.seq;
  s.sensor = m.sensor;
  s.num_beams = m.num_beams;
  s.sweep_duration = m.sweep_duration;
  setSweepFlags(m.flags, s);
  return s;
}

}  // namespace adit::msg
