#include "drivers/lidar_stream.hpp"

#include "drivers/rs16_decoder.hpp"
#include "drivers/vlp16_decoder.hpp"
#include "drivers/vlp32_decoder.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <stdexcept>

namespace adit::drivers {
namespace {

std::array<double, kBeams> elevationTable(const LidarStreamConfig& c) {
  if (beamsOf(c.model) != kBeams) {
    if (!c.elevations_deg.empty())
      throw std::invalid_argument("lidar driver: a vertical angle table is read for 16-beam heads only");
    return kVlp16ElevationsDeg;  // unused: 32-beam heads carry their own tables
  }
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
    : config_(config),
      sensor_time_(config.clock.source != TimeSource::kHost),
      host_time_fallback_(config.host_time_fallback),
      clock_config_(config.clock),
      clock_(config.clock),
      assembler_(config.sweep) {
  for (int id : config.accept_product_ids)
    if (id < 0 || id > 255) throw std::invalid_argument("lidar driver: product id " + std::to_string(id) + " is not a byte");
  makeDecoder(elevationTable(config), config.dual_return);
}

bool packetStampKey(LidarModel model, const std::uint8_t* data, std::size_t size, std::int64_t& key) {
  if (data == nullptr) return false;
  if (model == LidarModel::kRs16) {
    if (size != kRs16PacketSize) return false;
    const std::uint8_t* t = data + 20;  // year-2000, month, day, hour, minute, second, ms u16, us u16
    key = ((((((static_cast<std::int64_t>(t[0]) * 12 + t[1]) * 31 + t[2]) * 24 + t[3]) * 60 + t[4]) * 60 + t[5]) *
           1000000) + ((t[6] << 8) | t[7]) * 1000 + ((t[8] << 8) | t[9]);
    return true;
  }
  if (size != kVlp16PacketSize) return false;
  key = static_cast<std::int64_t>(data[1200]) | (static_cast<std::int64_t>(data[1201]) << 8) |
        (static_cast<std::int64_t>(data[1202]) << 16) | (static_cast<std::int64_t>(data[1203]) << 24);
  return true;
}

std::int64_t unwrapStampKey(LidarModel model, std::int64_t key, std::int64_t reference) {
  if (model == LidarModel::kRs16) return key;
  constexpr std::int64_t kHour = 3600000000LL;
  std::int64_t d = (key - reference) % kHour;
  if (d > kHour / 2) d -= kHour;
  if (d < -kHour / 2) d += kHour;
  return reference + d;
}

int beamsOf(LidarModel model) {
  return model == LidarModel::kVlp32c || model == LidarModel::kHdl32e ? kBeams32 : kBeams;
}

void LidarPacketStream::makeDecoder(const std::array<double, kBeams>& elevations, bool dual_return) {
  elevations_ = elevations;
  dual_return_ = dual_return;
  std::vector<std::uint8_t> products;
  for (int id : config_.accept_product_ids) products.push_back(static_cast<std::uint8_t>(id));
  if (beamsOf(config_.model) == kBeams32) {
    const Velodyne32 head = config_.model == LidarModel::kVlp32c ? Velodyne32::kVlp32c : Velodyne32::kHdl32e;
    firing_table_ = firingTable32(head);
    auto decoder = std::make_shared<Vlp32Decoder>(head, products);
    decode_ = [decoder](const std::uint8_t* d, std::size_t n, DecodedPacket& out) { return decoder->decode(d, n, out); };
    return;
  }
  firing_table_ = drivers::firingTable(BeamTable::fromElevationsDeg(elevations),
                                       config_.model == LidarModel::kVlp16 ? kVlp16FiringNs : kRs16FiringNs);
  if (config_.model == LidarModel::kVlp16) {
    auto decoder = std::make_shared<Vlp16Decoder>(elevations, products);
    decode_ = [decoder](const std::uint8_t* d, std::size_t n, DecodedPacket& out) { return decoder->decode(d, n, out); };
  } else {
    auto decoder = std::make_shared<Rs16Decoder>(elevations, dual_return);
    decode_ = [decoder](const std::uint8_t* d, std::size_t n, DecodedPacket& out) { return decoder->decode(d, n, out); };
  }
}

void LidarPacketStream::pushDeviceInfo(const std::uint8_t* data, std::size_t size) {
  Rs16Difop difop;
  if (config_.model != LidarModel::kRs16 || !parseRs16Difop(data, size, difop)) {
    health_.counters["bad_difop"] += 1;
    return;
  }
  health_.counters["difop"] += 1;
  // A table given in the configuration is the user's calibration and wins over the sensor's.
  const std::array<double, kBeams> elevations =
      difop.has_angles && config_.elevations_deg.empty() ? difop.elevation_deg : elevations_;
  if (elevations == elevations_ && difop.dual_return == dual_return_) return;
  try {
    makeDecoder(elevations, difop.dual_return);
  } catch (const std::invalid_argument&) {  // an angle table BeamTable refuses
    health_.counters["bad_difop"] += 1;
    return;
  }
  health_.counters["difop_applied"] += 1;
  spdlog::info("RS-16 DIFOP: {} return{}", difop.dual_return ? "dual" : "single",
               difop.has_angles ? ", calibrated vertical angles" : "");
}

void LidarPacketStream::count(const std::string& counter, std::int64_t& total, const std::string& what) {
  ++total;
  const std::int64_t n = ++health_.counters[counter];
  health_.last_error = what;
  if (worthLogging(n)) spdlog::warn("lidar packet skipped: {} ({} so far)", what, n);
}

void LidarPacketStream::push(const std::uint8_t* data, std::size_t size, std::int64_t host_receive_ns,
                             std::vector<LidarScan>& sweeps) {
  if (config_.model == LidarModel::kRs16 && size >= kRs16DifopMagic.size() &&
      std::equal(kRs16DifopMagic.begin(), kRs16DifopMagic.end(), data)) {
    pushDeviceInfo(data, size);
    return;
  }
  ++health_.inputs;
  PacketStatus status = decode_(data, size, packet_);
  if (status == PacketStatus::kOk && !packet_.stamp_valid && sensor_time_ && host_time_fallback_ && !placed_any_) {
    sensor_time_ = false;
    clock_config_.source = TimeSource::kHost;
    clock_ = PacketClock(clock_config_);
    health_.counters["host_time_fallback"] = 1;
    spdlog::warn("lidar packets carry no usable sensor time: using the receive (capture) times");
  }
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
  if (t->far_from_host) {
    const std::int64_t n = health_.counters["clock_not_utc"] += 1;
    if (n == 1) spdlog::warn("lidar stamp {} us is far from the receive time: time_source utc needs the sensor and the "
                             "host on UTC (GPS/PPS, chrony); use 'sensor' for a free-running clock", packet_.stamp_us);
  }
  placed_any_ = true;
  countLostPackets(t->first_firing_ns);
  health_.last_input_utime = t->first_firing_ns / 1000;
  const std::size_t before = sweeps.size();
  assembler_.add(packet_, t->first_firing_ns, sweeps);
  health_.outputs += static_cast<std::int64_t>(sweeps.size() - before);
  syncSweepCounters();
}

void LidarPacketStream::countLostPackets(std::int64_t first_firing_ns) {
  const std::int64_t spacing = last_first_ns_ < 0 ? 0 : first_firing_ns - last_first_ns_;
  last_first_ns_ = first_firing_ns;
  if (spacing <= 0) return;
  // Two equal spacings in a row (to 1 %) are the period or a multiple of it: the smallest such is the period.
  // A single odd spacing (a hole, a shifted clock) never sets it.
  if (last_spacing_ns_ > 0 && std::llabs(spacing - last_spacing_ns_) * 100 <= spacing &&
      (period_ns_ == 0 || spacing < period_ns_))
    period_ns_ = spacing;
  last_spacing_ns_ = spacing;
  // Longer holes restart the sweep and are counted as packet_gap by the assembler.
  const auto max_gap_ns = static_cast<std::int64_t>(config_.sweep.max_firing_gap_s * 1e9);
  if (period_ns_ == 0 || 2 * spacing < 3 * period_ns_ || spacing > max_gap_ns) return;
  health_.counters["lost_packets"] +=
      std::llround(static_cast<double>(spacing) / static_cast<double>(period_ns_)) - 1;
}

void LidarPacketStream::finish(std::vector<LidarScan>& sweeps) {
  const std::size_t before = sweeps.size();
  assembler_.flush(sweeps);
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
  if (s.flushed > 0) c["partial_sweep_published"] = s.flushed;
  health_.drops += s.partial + s.too_long - dropped_before;
}

}  // namespace adit::drivers
