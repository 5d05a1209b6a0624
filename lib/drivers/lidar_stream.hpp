// Everything between a UDP payload and a finished sweep, without the socket: decode (VLP-16 or RS-16),
// place on the time line (PacketClock), cut into sweeps (SweepAssembler), and count what went wrong.
// Pure: the receive time comes with each packet, so a recorded packet stream replays identically.
#pragma once

#include "core/types.hpp"
#include "drivers/firing.hpp"
#include "drivers/packet_clock.hpp"
#include "drivers/sweep_assembler.hpp"
#include "runtime/health.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace adit::drivers {

enum class LidarModel { kVlp16, kRs16 };

struct LidarStreamConfig {
  LidarModel model = LidarModel::kVlp16;
  // Elevation (deg) of each laser id in packet slot order; empty = the model's nominal table
  // (VLP-16: -15, 1, -13, 3, ...; RS-16: -15, -13, ..., -1, 15, 13, ..., 1).
  std::vector<double> elevations_deg;
  PacketClockConfig clock;
  SweepAssemblerConfig sweep;
};

// Counter names in Health::counters:
//   malformed packets (Health::errors): wrong_size, bad_magic, bad_block_flag, bad_azimuth, bad_timestamp,
//     unknown_product, unknown_return_mode;
//   skipped packets (Health::drops): time_backwards;
//   sweeps not published (Health::drops): partial_sweep, sweep_too_long;
//   events: packet_gap, time_reanchor, time_shifted, empty_sweep.
class LidarPacketStream {
 public:
  // Throws std::invalid_argument on a bad elevation table.
  explicit LidarPacketStream(const LidarStreamConfig& config);

  // One UDP payload that arrived at host_receive_ns (ns since 1970). Finished sweeps are appended to `sweeps`.
  void push(const std::uint8_t* data, std::size_t size, std::int64_t host_receive_ns,
            std::vector<LidarScan>& sweeps);

  // inputs = packets, outputs = sweeps published.
  const runtime::Health& health() const { return health_; }
  // The head's firing table (for msg::encodeSweep).
  const msg::FiringTable& firingTable() const { return firing_table_; }

 private:
  void count(const std::string& counter, std::int64_t& total, const std::string& what);
  void syncSweepCounters();

  std::function<PacketStatus(const std::uint8_t*, std::size_t, DecodedPacket&)> decode_;
  bool sensor_time_;
  PacketClock clock_;
  SweepAssembler assembler_;
  DecodedPacket packet_;  // reused between packets
  msg::FiringTable firing_table_;
  runtime::Health health_;
};

}  // namespace adit::drivers
