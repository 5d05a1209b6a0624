#include "drivers/packet_clock.hpp"

namespace adit::drivers {
namespace {

constexpr std::int64_t kHourUs = 3600LL * 1000000;

}  // namespace

std::optional<PacketTime> PacketClock::place(const DecodedPacket& packet, std::int64_t host_receive_ns) {
  return config_.source == TimeSource::kSensor ? placeBySensor(packet, host_receive_ns)
                                               : placeByHost(packet, host_receive_ns);
}

bool PacketClock::accept(std::int64_t first_ns, const DecodedPacket& packet) {
  if (have_last_ && first_ns <= last_end_ns_) return false;
  have_last_ = true;
  last_end_ns_ = first_ns + packet.duration_ns;
  return true;
}

std::optional<PacketTime> PacketClock::placeBySensor(const DecodedPacket& packet, std::int64_t host_receive_ns) {
  const auto max_jump_us = static_cast<std::int64_t>(config_.max_jump_s * 1e6);
  std::int64_t stamp = packet.stamp_us;
  if (anchored_ && packet.clock == SensorClock::kMicrosPastHour) {
    // Unwrap: the stamp nearest to the last one, modulo an hour.
    stamp = packet.stamp_us + hour_wraps_ * kHourUs;
    if (stamp < last_stamp_us_ - kHourUs / 2) stamp += kHourUs;
    else if (stamp > last_stamp_us_ + kHourUs / 2) stamp -= kHourUs;
  }
  PacketTime t;
  const std::int64_t step = stamp - last_stamp_us_;
  if (!anchored_ || step > max_jump_us || step < -max_jump_us) {
    t.reanchored = anchored_;
    const std::int64_t host_first = host_receive_ns - packet.duration_ns;
    // Never re-anchor behind what was already published.
    const std::int64_t first = have_last_ && host_first <= last_end_ns_ ? last_end_ns_ + 1 : host_first;
    anchored_ = true;
    anchor_host_ns_ = first;
    anchor_stamp_us_ = packet.stamp_us;  // raw: the hour count restarts at this anchor
    last_stamp_us_ = packet.stamp_us;
    hour_wraps_ = 0;
    accept(first, packet);
    t.first_firing_ns = first;
    return t;
  }
  t.first_firing_ns = anchor_host_ns_ + (stamp - anchor_stamp_us_) * 1000;
  if (!accept(t.first_firing_ns, packet)) return std::nullopt;
  if (packet.clock == SensorClock::kMicrosPastHour) hour_wraps_ = (stamp - packet.stamp_us) / kHourUs;
  last_stamp_us_ = stamp;
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
