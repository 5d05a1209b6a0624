// Puts each decoded packet on the output time line (ns since 1970, host clock), which must never go back.
//
// kSensor: the sensor's own stamp gives the firing times (exact spacing, no network jitter). Its zero is
//   arbitrary and its crystal runs at its own rate (a free-running Velodyne counts from power-on unless a GPS
//   sets it; a RoboSense without sync starts at some default date), so the stamps go through the IMU's
//   estimator (clock_sync.hpp): each packet's (stamp, host receive time - packet duration) pair feeds a
//   filtered offset and drift, and the packet's first firing is its stamp mapped through them, minus the
//   configured transport delay. The Velodyne's us-past-the-hour stamp is unwrapped at the hour first. A jump
//   of the sensor clock by more than max_jump (GPS lock, a reset) restarts the estimator (re-anchor), never
//   behind what was already published. A refit may move the line back by microseconds (up to a jitter's
//   worth while the first windows fill): a packet that would overlap the previous one is shifted forward.
// kUtc: the sensor's clock is UTC (GPS / PPS) and so is the host's (chrony, PTP): the stamp is the first
//   firing's time as it is, the Velodyne's hour taken as the one that puts the stamp nearest to the receive
//   time. A stamp further than max_jump from the receive time is still used, and flagged (far_from_host):
//   one of the clocks is not on UTC.
// kHost: the host receive time (kernel stamp) minus the packet's duration is the first firing. Network
//   jitter can make a packet start a little before the previous one ended; up to one packet duration of
//   overlap is shifted forward (counted), more is a time step back.
// A packet that would still start before the previous packet's last firing (kHost, kUtc), or whose sensor
// stamp is not past the previous packet's (kSensor: a repeated or late packet), is refused (counted by the caller
// as "time_backwards") and the clock stays as it was.
#pragma once

#include "drivers/clock_sync.hpp"
#include "drivers/firing.hpp"

#include <cstdint>
#include <optional>

namespace adit::drivers {

enum class TimeSource { kSensor, kUtc, kHost };

struct PacketClockConfig {
  TimeSource source = TimeSource::kSensor;
  // Sensor clock steps larger than this (either way, s) re-anchor on the host clock (kUtc: a stamp this far
  // from the receive time is flagged). 1 s: far above the 1.3 ms packet spacing and any network delay, far
  // below a GPS correction of a free-running clock.
  double max_jump_s = 1.0;
  // kSensor: the offset / drift estimator; its transport_delay_s is the fixed delay from a packet's last
  // firing to its receive time (the sensor's send and the wire), which no one-way estimate can see.
  ClockSyncConfig sync;
};

struct PacketTime {
  std::int64_t first_firing_ns = 0;  // output time of the packet's first firing
  bool reanchored = false;           // kSensor: the sensor clock jumped and was re-anchored
  bool shifted = false;              // shifted forward over the previous packet's end
  bool far_from_host = false;        // kUtc: the stamp is further than max_jump from the receive time
};

class PacketClock {
 public:
  explicit PacketClock(const PacketClockConfig& config) : config_(config), sync_(syncConfig()) {}

  // host_receive_ns: when the packet arrived (ns since 1970). nullopt: the packet would go back in time.
  std::optional<PacketTime> place(const DecodedPacket& packet, std::int64_t host_receive_ns);

 private:
  std::optional<PacketTime> placeBySensor(const DecodedPacket& packet, std::int64_t host_receive_ns);
  std::optional<PacketTime> placeByUtc(const DecodedPacket& packet, std::int64_t host_receive_ns);
  std::optional<PacketTime> placeByHost(const DecodedPacket& packet, std::int64_t host_receive_ns);
  // Accepts a packet starting at first_ns if it does not start before the previous one ended.
  bool accept(std::int64_t first_ns, const DecodedPacket& packet);
  // The Velodyne's us-past-the-hour stamp nearest to the last one, modulo an hour (other clocks unchanged).
  std::int64_t unwrap(const DecodedPacket& packet) const;
  // config_.sync in nanoseconds.
  ClockSyncConfig syncConfig() const;

  PacketClockConfig config_;
  bool anchored_ = false;
  DeviceClockSync sync_;               // kSensor: sensor stamp -> host time, restarted at each re-anchor
  std::int64_t base_stamp_us_ = 0;     // the estimator's zeros: the anchor packet's stamp
  std::int64_t base_host_ns_ = 0;      // and its first firing's receive-time estimate
  std::int64_t last_stamp_us_ = 0;     // unwrapped stamp of the last accepted packet
  std::int64_t last_duration_ns_ = 0;  // and its duration
  std::int64_t hour_wraps_ = 0;        // kMicrosPastHour: hours added to the raw stamp
  bool have_last_ = false;
  std::int64_t last_end_ns_ = 0;       // output time of the last accepted packet's last firing
};

}  // namespace adit::drivers
