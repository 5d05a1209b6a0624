// Cuts the stream of timed firings into sweeps (one revolution each), as adit::LidarScan:
//  - a sweep ends where the azimuth passes the cut angle: the firing whose azimuth, measured from the cut,
//    drops back by more than half a turn begins the next sweep, so every firing lands in exactly one sweep;
//  - utime = the sweep's last firing (returns or not), each point's dt = its firing time minus that (<= 0),
//    sweep_duration = last firing - first firing;
//  - the first sweep after a start, a lost stretch of packets (gap) or a stalled head (too long) is
//    incomplete and is dropped, never published half-empty.
// Pure: times come with the firings; no clock, no I/O.
#pragma once

#include "core/types.hpp"
#include "drivers/firing.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace adit::drivers {

struct SweepAssemblerConfig {
  // Sensor azimuth (deg, clockwise from +x) where one sweep ends and the next begins. 180 = straight behind
  // the robot (lidar mounted facing forward): the seam, where the first and last firings of a sweep meet and
  // motion distortion is largest before deskew, lies on the side the robot has already mapped.
  double cut_azimuth_deg = 180.0;
  // A sweep longer than this (s) means the head stalled or slowed down: dropped. 0.25 s: the slowest VLP-16 /
  // RS-16 rotation (300 rpm) takes 0.2 s.
  double max_sweep_duration_s = 0.25;
  // Firings further apart than this (s) mean lost packets: the sweep in progress is dropped. 10 ms ~ 7 packets
  // (about 36 deg at 10 Hz); single lost packets (1.3 ms) only leave a small hole and are kept.
  double max_firing_gap_s = 0.010;
  std::string sensor = "vlp16";  // LidarScan::sensor
  int num_beams = kBeams;         // LidarScan::num_beams
};

struct SweepStats {
  std::int64_t sweeps = 0;          // published
  std::int64_t partial = 0;         // revolutions dropped: began mid-way (start, after a gap or a stall)
  std::int64_t too_long = 0;        // dropped: longer than max_sweep_duration_s
  std::int64_t gaps = 0;            // firing gaps longer than max_firing_gap_s
  std::int64_t empty = 0;           // published with no point (every firing without return)
  std::int64_t flushed = 0;         // published partial at the end of the stream
};

class SweepAssembler {
 public:
  explicit SweepAssembler(const SweepAssemblerConfig& config);

  // Adds one packet whose first firing is at first_firing_ns (output time line, ns); complete sweeps are
  // appended to `sweeps`. Packets must come in time order (PacketClock guarantees it).
  void add(const DecodedPacket& packet, std::int64_t first_firing_ns, std::vector<LidarScan>& sweeps);

  // End of the stream (a recording's end): the sweep in progress, if it holds a point, is appended flagged
  // `partial` (whether or not it began at a cut), so a recording's last firings are not lost.
  void flush(std::vector<LidarScan>& sweeps);

  const SweepStats& stats() const { return stats_; }

 private:
  struct TimedPoint {
    LidarPoint point;
    std::int64_t t_ns;
  };
  void addFiring(const Firing& f, std::int64_t t_ns, std::vector<LidarScan>& sweeps);
  void finishSweep(std::vector<LidarScan>& sweeps);
  void publish(bool partial, std::vector<LidarScan>& sweeps);
  void restart(bool complete, std::int64_t t_ns);

  SweepAssemblerConfig config_;
  std::int64_t max_duration_ns_, max_gap_ns_;
  SweepStats stats_;
  std::vector<TimedPoint> points_;  // the sweep in progress
  bool complete_ = false;           // the sweep in progress began at a cut
  bool started_ = false;            // at least one firing seen
  std::int64_t first_ns_ = 0, last_ns_ = 0;
  double last_phase_ = 0.0;         // azimuth of the last firing measured from the cut, [0, 360)
};

}  // namespace adit::drivers
