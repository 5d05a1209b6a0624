#include "sources/sim_source.hpp"

#include "msg/convert.hpp"

#include <cmath>
#include "msg/encode.hpp"

namespace adit::sources {

msg::FiringTable firingTableOf(const sim::LidarProfile& profile) {
  msg::FiringTable t;
  const std::vector<std::uint16_t> rings = profile.rings();
  t.ring_offset_ns.assign(rings.size(), 0);
  for (std::size_t slot = 0; slot < rings.size(); ++slot)
    t.ring_offset_ns[rings[slot]] = static_cast<std::int32_t>(std::lround(static_cast<double>(slot) * profile.firing_slot * 1e9));
  return t;
}

}  // namespace adit::sources

namespace adit::sources {

SimSource::SimSource(const sim::SimConfig& config, SimChannels channels, SimStalls stalls)
    : simulator_(config),
      channels_(std::move(channels)),
      stalls_(stalls),
      firing_table_(firingTableOf(simulator_.lidar().profile())) {}

double SimSource::progress() const {
  const auto total = simulator_.numSweeps();
  return total > 0 ? static_cast<double>(sweeps_) / static_cast<double>(total) : 1.0;
}

bool SimSource::next(runtime::OutgoingMessage& out) {
  if (pending_truth_) {
    out = std::move(*pending_truth_);
    pending_truth_.reset();
    ++health_.outputs;
    return true;
  }
  sim::SimEvent event;
  for (;;) {  // skip what a stalled stream would not have published
    if (!simulator_.next(event)) return false;
    const bool scan = event.kind == sim::SimEvent::Kind::Scan, imu = event.kind == sim::SimEvent::Kind::Imu;
    const std::int64_t utime = scan ? event.scan.utime : imu ? event.imu.utime : event.wheel.utime;
    if (first_utime_ < 0) first_utime_ = utime;
    if (scan) ++sweeps_;
    const double t_s = static_cast<double>(utime - first_utime_) * 1e-6;
    if (event.kind == sim::SimEvent::Kind::Wheel) {
      if (channels_.wheel_odom.empty()) continue;
      break;
    }
    if (imu && channels_.imu.empty()) continue;
    if (!(scan ? stalls_.lidar : stalls_.imu).covers(t_s)) break;
    if (imu) ++imu_seq_;
  }
  if (event.kind == sim::SimEvent::Kind::Wheel) {
    adit::wheel_odom_t m = msg::toMessage(event.wheel);
    m.header.seq = wheel_seq_++;
    out = {channels_.wheel_odom, msg::encode(m), event.wheel.utime};
    ++health_.outputs;
    return true;
  }
  if (event.kind == sim::SimEvent::Kind::Scan) {
    for (const auto& observe : sweep_observers_) observe(event.scan);
    out = {channels_.lidar, {}, event.scan.utime};
    if (channels_.sweep_bytes)
      out.data = channels_.compact_sweeps ? msg::encode(msg::encodeSweep(event.scan, &firing_table_))
                                          : msg::encode(msg::toMessage(event.scan));
    truth_.push_back(event.truth);
    if (!channels_.ground_truth.empty()) {
      PoseEstimate truth;
      truth.utime = event.truth.utime;
      truth.pose = event.truth.pose;
      truth.covariance.setZero();
      adit::odometry_t t = msg::toMessage(truth, nullptr);
      t.header.seq = truth_seq_++;
      pending_truth_ = runtime::OutgoingMessage{channels_.ground_truth, msg::encode(t), truth.utime};
    }
  } else {
    for (const auto& observe : imu_observers_) observe(event.imu);
    adit::imu_t m = msg::toMessage(event.imu);
    m.header.seq = imu_seq_++;
    out = {channels_.imu, msg::encode(m), event.imu.utime};
  }
  ++health_.outputs;
  return true;
}

}  // namespace adit::sources
