// One time base for a device without a common clock (an IMU on a serial port stamps samples with its own
// microsecond counter since power-on). Each sample gives device time t_d and host receive time t_h:
//
//     t_h = t_d + offset(t_d) + transport_delay + jitter,   jitter >= 0 (queues, USB polling, the scheduler)
//
// Jitter only ever delays, so the least-delayed sample of a window lies closest to offset + delay. The
// estimator keeps the minimum of t_h - t_d per window of device time (1 s), fits a line (offset and drift)
// through the last windows' minima by least squares, and maps t_d to host time with it, minus the transport
// delay (a fixed delay cannot be told from an offset without a round trip: it is configured, e.g. the
// frame's bytes at the baud rate). A device clock that jumps (reset, wrap) is followed after a few samples
// that agree on the new offset. Output stamps never go backwards. Deterministic: input stamps only.
// The lidar's packet stamps go through the same estimator (packet_clock.hpp), in nanoseconds.
#pragma once

#include <cstdint>
#include <deque>

namespace adit::drivers {

struct ClockSyncConfig {
  double window_s = 1.0;          // device time per minimum
  int windows = 30;               // minima in the line fit (30 s: drift of a crystal is stable over that)
  double transport_delay_s = 0;   // fixed delay subtracted (bytes on the wire at the baud rate, ...)
  double max_jump_s = 0.5;        // a sample this far from the fit is an outlier, or a clock jump
  int jump_confirm = 5;           // consecutive far samples that agree: the device clock jumped
  double ticks_per_s = 1e6;       // unit of the stamps in and out: 1e6 = microseconds, 1e9 = nanoseconds
};

class DeviceClockSync {
 public:
  explicit DeviceClockSync(ClockSyncConfig config = {});

  // Adds a sample (device and host receive time, in ticks) and returns its host-time stamp (ticks).
  std::int64_t stamp(std::int64_t device_t, std::int64_t host_t);
  // The current estimate of host - device at device time t (offset + drift, without the transport delay).
  double offsetAt(std::int64_t device_t) const;
  double driftPpm() const { return slope_ * 1e6; }
  std::int64_t clockJumps() const { return jumps_; }

 private:
  struct Minimum {
    std::int64_t device_t;
    double offset;
  };
  void refit();
  void reset();
  // The fit's host time of device_t, minus the transport delay, never before the previous stamp.
  std::int64_t hostStamp(std::int64_t device_t);

  ClockSyncConfig config_;
  std::deque<Minimum> minima_;  // closed windows, oldest first
  Minimum current_{0, 0};       // the open window's minimum
  bool have_current_ = false;
  std::int64_t window_start_ = 0;
  std::int64_t ref_t_ = 0;     // the fit: offset = intercept_ + slope_ * (t - ref_t_)
  double intercept_ = 0, slope_ = 0;
  bool fitted_ = false;
  int far_in_a_row_ = 0;
  double far_offset_ = 0;
  std::int64_t jumps_ = 0;
  std::int64_t last_out_ = INT64_MIN;
};

}  // namespace adit::drivers
