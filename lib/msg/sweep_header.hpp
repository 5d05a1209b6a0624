// The per-sweep fields that the full (point_cloud_t) and the compact (lidar_scan_t) sweep messages share,
// read into a LidarScan without its points. Both types name these fields alike and use point_cloud_t's flags.
#pragma once

#include "core/types.hpp"

#include <adit/point_cloud_t.hpp>

namespace adit::msg {

template <class SweepMessage>
LidarScan sweepHeader(const SweepMessage& m) {
  LidarScan s;
  s.utime = m.header.utime;
  s.seq = m.header.seq;
  s.sensor = m.sensor;
  s.num_beams = m.num_beams;
  s.sweep_duration = m.sweep_duration;
  s.has_ring = (m.flags & adit::point_cloud_t::FLAG_HAS_RING) != 0;
  s.has_time = (m.flags & adit::point_cloud_t::FLAG_HAS_TIME) != 0;
  s.deskewed = (m.flags & adit::point_cloud_t::FLAG_DESKEWED) != 0;
  return s;
}

}  // namespace adit::msg
