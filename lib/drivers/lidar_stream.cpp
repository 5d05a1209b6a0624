#include "drivers/lidar_stream.hpp"

#include "drivers/rs16_decoder.hpp"
#include "drivers/vlp16_decoder.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <memory>
#include <stdexcept>

namespace adit::drivers {
namespace {

std::array<double, kBeams> elevationTable(const LidarStreamConfig& c) {
  if (c.elevations_deg.empty()) return c.model == LidarModel::kVlp16 ? kVlp16ElevationsDeg : kRs16ElevationsDeg;
  if (c.elevations_deg.size() != kBeams)
    throw std::invalid_argument("lidar driver: the elevation table needs 16 angles, got " +
                                std::to_string(c.elevations_deg.size()));
  std::array<double, kBeams> t{};
  std::copy(c.elevations_deg.begin(), c.elevations_deg.end(), t.begin());
  return t;
}

// A flood of bad packets (wrong port, DIFOP on the MSOP port) must not flood the log: 1st, 10th, 100th, ...
bool worthLogging(std::int64_t n) {
  while (n % 10 == 0) n /= 10;
  return n == 1;
}

}  // namespace

LidarPacketStream::LidarPacketStream(const LidarStreamConfig& config)
    : sensor_time_(config.clock.source == TimeSource::kSensor), clock_(config.clock), assembler_(config.sweep) {
  const std::array<double, kBeams> elevations = elevationTable(config);
  firing_table_ = drivers::firingTable(BeamTable::fromElevationsDeg(elevations),
                                       config.model == LidarModel::kVlp16 ? kVlp16FiringNs : kRs16FiringNs);
  if (config.model == LidarModel::kVlp16) {
    auto decoder = std::make_shared<Vlp16Decoder>(elevations);
    decode_ = [decoder](const std::uint8_t* d, std::size_t n, DecodedPacket& out) { return decoder->decode(d, n, out); };
  } else {
    auto decoder = std::make_shared<Rs16Decoder>(elevations);
    decode_ = [decoder](const std::uint8_t* d, std::size_t n, DecodedPacket& out) { return decoder->decode(d, n, out); };
  }
}

void LidarPacketStream::count(const std::string& counter, std::int64_t& total, const std::string& what) {
  ++total;
  const std::int64_t n = ++health_.counters[counter];
  health_.last_error = what;
  if (worthLogging(n)) spdlog::warn("lidar packet skipped: {} ({} so far)", what, n);
}

void LidarPacketStream::push(const std::uint8_t* data, std::size_t size, std::int64_t host_receive_ns,
                             std::vector<LidarScan>& sweeps) {
  ++health_.inputs;
  PacketStatus status = decode_(data, size, packet_);
  if (status == PacketStatus::kOk && !packet_.stamp_valid && sensor_time_) status = PacketStatus::kBadTimestamp;
  if (status != PacketStatus::kOk) {
    count(counterName(status), health_.errors,
          std::string(counterName(status)) + " (" + std::to_string(size) + " bytes)");
    return;
  }
  const std::optional<PacketTime> t = clock_.place(packet_, host_receive_ns);
  if (!t) {
    count("time_backwards", health_.drops, "time_backwards: packet stamp " + std::to_string(packet_.stamp_us) + " us");
    return;
  }
  if (t->reanchored) {
    health_.counters["time_reanchor"] += 1;
    spdlog::warn("lidar clock jumped (packet stamp {} us): re-anchored on the host clock", packet_.stamp_us);
  }
  if (t->shifted) health_.counters["time_shifted"] += 1;
  health_.last_input_utime = t->first_firing_ns / 1000;
  const std::size_t before = sweeps.size();
  assembler_.add(packet_, t->first_firing_ns, sweeps);
  health_.outputs += static_cast<std::int64_t>(sweeps.size() - before);
  syncSweepCounters();
}

void LidarPacketStream::syncSweepCounters() {
  const SweepStats& s = assembler_.stats();
  auto& c = health_.counters;
  const std::int64_t dropped_before = c["partial_sweep"] + c["sweep_too_long"];
  c["partial_sweep"] = s.partial;
  c["sweep_too_long"] = s.too_long;
  c["packet_gap"] = s.gaps;
  c["empty_sweep"] = s.empty;
  health_.drops += s.partial + s.too_long - dropped_before;
}

}  // namespace adit::drivers
