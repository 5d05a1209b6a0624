#include "drivers/sweep_assembler.hpp"

#include <cmath>

namespace adit::drivers {

SweepAssembler::SweepAssembler(const SweepAssemblerConfig& config)
    : config_(config),
      max_duration_ns_(static_cast<std::int64_t>(config.max_sweep_duration_s * 1e9)),
      max_gap_ns_(static_cast<std::int64_t>(config.max_firing_gap_s * 1e9)) {}

void SweepAssembler::add(const DecodedPacket& packet, std::int64_t first_firing_ns, std::vector<LidarScan>& sweeps) {
  for (const Firing& f : packet.firings) addFiring(f, first_firing_ns + f.offset_ns, sweeps);
}

void SweepAssembler::restart(bool complete, std::int64_t t_ns) {
  points_.clear();
  complete_ = complete;
  first_ns_ = t_ns;
}

void SweepAssembler::addFiring(const Firing& f, std::int64_t t_ns, std::vector<LidarScan>& sweeps) {
  double phase = std::fmod(static_cast<double>(f.azimuth_deg) - config_.cut_azimuth_deg, 360.0);
  if (phase < 0) phase += 360.0;
  if (!started_) {
    started_ = true;
    restart(false, t_ns);
  } else if (t_ns - last_ns_ > max_gap_ns_) {
    ++stats_.gaps;  // the revolution is counted as partial when it ends
    restart(false, t_ns);
  } else if (phase < last_phase_ - 180.0) {
    finishSweep(sweeps);
    restart(true, t_ns);
  } else if (t_ns - first_ns_ > max_duration_ns_) {
    ++stats_.too_long;
    restart(false, t_ns);
  }
  last_ns_ = t_ns;
  last_phase_ = phase;
  if (!f.has_return) return;
  TimedPoint tp;
  tp.point.p = f.p;
  tp.point.intensity = f.intensity;
  tp.point.ring = f.ring;
  tp.t_ns = t_ns;
  points_.push_back(tp);
}

void SweepAssembler::finishSweep(std::vector<LidarScan>& sweeps) {
  if (!complete_) {
    ++stats_.partial;
    return;
  }
  if (last_ns_ - first_ns_ > max_duration_ns_) {
    ++stats_.too_long;
    return;
  }
  publish(false, sweeps);
}

void SweepAssembler::flush(std::vector<LidarScan>& sweeps) {
  if (!started_ || points_.empty()) return;
  ++stats_.flushed;
  publish(true, sweeps);
  points_.clear();
  complete_ = false;
  started_ = false;
}

void SweepAssembler::publish(bool partial, std::vector<LidarScan>& sweeps) {
  LidarScan scan;
  scan.partial = partial;
  scan.utime = last_ns_ / 1000;  // dt below is exact to the ns; utime is that instant's microsecond
  scan.seq = stats_.sweeps++;
  scan.sensor = config_.sensor;
  scan.num_beams = config_.num_beams;
  scan.sweep_duration = static_cast<float>(static_cast<double>(last_ns_ - first_ns_) * 1e-9);
  scan.has_ring = true;
  scan.has_time = true;
  scan.points.reserve(points_.size());
  for (const TimedPoint& tp : points_) {
    scan.points.push_back(tp.point);
    scan.points.back().dt = static_cast<float>(static_cast<double>(tp.t_ns - last_ns_) * 1e-9);
  }
  if (scan.points.empty()) ++stats_.empty;
  sweeps.push_back(std::move(scan));
}

}  // namespace adit::drivers
