#include "drivers/packet_clock.hpp"

#include <cmath>

namespace adit::drivers {
namespace {

constexpr std::int64_t kHourUs = 3600LL * 1000000;

}  // namespace

std::optional<PacketTime> PacketClock::place(const DecodedPacket& packet, std::int64_t host_receive_ns) {
  switch (config_.source) {
    case TimeSource::kSensor: return placeBySensor(packet, host_receive_ns);
    case TimeSource::kUtc: return placeByUtc(packet, host_receive_ns);
    case TimeSource::kHost: break;
  }
  return placeByHost(packet, host_receive_ns);
}

bool PacketClock::accept(std::int64_t first_ns, const DecodedPacket& packet) {
  if (have_last_ && first_ns <= last_end_ns_) return false;
  have_last_ = true;
  last_end_ns_ = first_ns + packet.duration_ns;
  return true;
}

ClockSyncConfig PacketClock::syncConfig() const {
  ClockSyncConfig c = config_.sync;
  c.ticks_per_s = 1e9;
  return c;
}

std::int64_t PacketClock::unwrap(const DecodedPacket& packet) const {
  if (!anchored_ || packet.clock != SensorClock::kMicrosPastHour) return packet.stamp_us;
  std::int64_t stamp = packet.stamp_us + hour_wraps_ * kHourUs;
  if (stamp < last_stamp_us_ - kHourUs / 2) stamp += kHourUs;
  else if (stamp > last_stamp_us_ + kHourUs / 2) stamp -= kHourUs;
  return stamp;
}

std::optional<PacketTime> PacketClock::placeBySensor(const DecodedPacket& packet, std::int64_t host_receive_ns) {
  const auto max_jump_us = static_cast<std::int64_t>(config_.max_jump_s * 1e6);
  std::int64_t stamp = unwrap(packet);
  PacketTime t;
  const std::int64_t step = stamp - last_stamp_us_;
  const std::int64_t host_first_ns = host_receive_ns - packet.duration_ns;
  if (!anchored_ || step > max_jump_us || step < -max_jump_us) {
    t.reanchored = anchored_;
    anchored_ = true;
    sync_ = DeviceClockSync(syncConfig());  // a new sensor clock: nothing of the old fit applies
    stamp = packet.stamp_us;                // raw: the hour count restarts here
    hour_wraps_ = 0;
    base_stamp_us_ = stamp;
    base_host_ns_ = host_first_ns;
  } else if (stamp * 1000 < last_stamp_us_ * 1000 + last_duration_ns_) {
    return std::nullopt;  // the sensor says this packet is not after the last one: a repeat or a late one
  }
  // The pair is taken at the first firing (the receive time is of the last one), in nanoseconds from the
  // anchor packet's, so the estimator's doubles hold them exactly. Its output never goes back.
  t.first_firing_ns = base_host_ns_ + sync_.stamp((stamp - base_stamp_us_) * 1000, host_first_ns - base_host_ns_);
  if (have_last_ && t.first_firing_ns <= last_end_ns_) {
    t.first_firing_ns = last_end_ns_ + 1;
    t.shifted = !t.reanchored;
  }
  accept(t.first_firing_ns, packet);
  if (packet.clock == SensorClock::kMicrosPastHour) hour_wraps_ = (stamp - packet.stamp_us) / kHourUs;
  last_stamp_us_ = stamp;
  last_duration_ns_ = packet.duration_ns;
  return t;
}

std::optional<PacketTime> PacketClock::placeByUtc(const DecodedPacket& packet, std::int64_t host_receive_ns) {
  const std::int64_t receive_us = host_receive_ns / 1000;
  std::int64_t stamp = packet.stamp_us;
  if (packet.clock == SensorClock::kMicrosPastHour) {
    stamp += receive_us - receive_us % kHourUs;  // the receive time's hour, or its neighbour nearer the stamp
    if (stamp > receive_us + kHourUs / 2) stamp -= kHourUs;
    else if (stamp < receive_us - kHourUs / 2) stamp += kHourUs;
  }
  PacketTime t;
  t.first_firing_ns = stamp * 1000;
  const double off_s = static_cast<double>(host_receive_ns - packet.duration_ns - t.first_firing_ns) * 1e-9;
  t.far_from_host = std::abs(off_s) > config_.max_jump_s;
  if (!accept(t.first_firing_ns, packet)) return std::nullopt;
  return t;
}

std::optional<PacketTime> PacketClock::placeByHost(const DecodedPacket& packet, std::int64_t host_receive_ns) {
  PacketTime t;
  t.first_firing_ns = host_receive_ns - packet.duration_ns;
  if (have_last_ && t.first_firing_ns <= last_end_ns_ && last_end_ns_ - t.first_firing_ns <= packet.duration_ns) {
    t.first_firing_ns = last_end_ns_ + 1;
    t.shifted = true;
  }
  if (!accept(t.first_firing_ns, packet)) return std::nullopt;
  return t;
}

}  // namespace adit::drivers
