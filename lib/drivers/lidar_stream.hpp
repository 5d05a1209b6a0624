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
#include <array>
#include <functional>
#include <string>
#include <vector>

namespace adit::drivers {

enum class LidarModel { kVlp16, kRs16, kVlp32c, kHdl32e };
// Beams of a model's head (16 or 32).
int beamsOf(LidarModel model);
// A key that orders a model's data packets by their own stamp (Velodyne: us past the hour, to be compared
// modulo the hour; RS-16: the header's date and time, monotonic within a month's days), read without decoding;
// false for a payload of the wrong size.
bool packetStampKey(LidarModel model, const std::uint8_t* data, std::size_t size, std::int64_t& key);
// Velodyne stamps wrap every hour: the key of `key` nearest to `reference` (keys of other models unchanged).
std::int64_t unwrapStampKey(LidarModel model, std::int64_t key, std::int64_t reference);

struct LidarStreamConfig {
  LidarModel model = LidarModel::kVlp16;
  // Elevation (deg) of each laser id in packet slot order; empty = the model's nominal table
  // (VLP-16: -15, 1, -13, 3, ...; RS-16: -15, -13, ..., -1, 15, 13, ..., 1).
  std::vector<double> elevations_deg;
  PacketClockConfig clock;
  SweepAssemblerConfig sweep;
  // Sensor time only: if the first decodable packet's stamp is unusable (an RS-16 whose clock was never
  // set), run on the receive times instead (counter host_time_fallback). Recordings turn it on: their
  // capture times are the only other clock; live, a bad sensor clock is reported instead.
  bool host_time_fallback = false;
  // VLP-16: product ids (factory byte 1205) accepted besides 0x22 (VLP-16) and 0 (old firmware), for units
  // that announce another product but send VLP-16 packets (lidar_driver.accept_product_ids).
  std::vector<int> accept_product_ids;
  // RS-16: the return mode until a DIFOP packet says otherwise.
  bool dual_return = false;
};

// Counter names in Health::counters:
//   malformed packets (Health::errors): wrong_size, bad_magic, bad_block_flag, bad_azimuth, bad_timestamp,
//     unknown_product, unknown_return_mode;
//   skipped packets (Health::drops): time_backwards;
//   sweeps not published (Health::drops): partial_sweep, sweep_too_long;
//   events: packet_gap, time_reanchor, time_shifted, clock_not_utc, empty_sweep, partial_sweep_published;
//   lost_packets: packets missing from the stream in holes shorter than a packet_gap (lost on the link, or
//     come too late and skipped as time_backwards), from the spacing of the stamps: the packet period is the
//     smallest spacing seen twice in a row, and a hole of k periods is k - 1 lost packets.
class LidarPacketStream {
 public:
  // Throws std::invalid_argument on a bad elevation table.
  explicit LidarPacketStream(const LidarStreamConfig& config);

  // One UDP payload that arrived at host_receive_ns (ns since 1970). Finished sweeps are appended to `sweeps`.
  void push(const std::uint8_t* data, std::size_t size, std::int64_t host_receive_ns,
            std::vector<LidarScan>& sweeps);

  // RS-16 DIFOP packet (port 7788; also recognised by its header on the data port): its return mode, and its
  // vertical-angle calibration unless the config gave a table, replace what the decoder used (counters
  // difop, difop_applied). Anything else is counted as bad_difop.
  void pushDeviceInfo(const std::uint8_t* data, std::size_t size);

  // End of the packets (a recording's end): the sweep in progress is appended, flagged partial
  // (counter partial_sweep_published).
  void finish(std::vector<LidarScan>& sweeps);

  // inputs = packets, outputs = sweeps published.
  const runtime::Health& health() const { return health_; }
  // The head's firing table (for msg::encodeSweep).
  const msg::FiringTable& firingTable() const { return firing_table_; }

 private:
  void count(const std::string& counter, std::int64_t& total, const std::string& what);
  void syncSweepCounters();

  void makeDecoder(const std::array<double, kBeams>& elevations, bool dual_return);
  void countLostPackets(std::int64_t first_firing_ns);

  LidarStreamConfig config_;
  std::array<double, kBeams> elevations_{};
  bool dual_return_ = false;
  std::function<PacketStatus(const std::uint8_t*, std::size_t, DecodedPacket&)> decode_;
  bool sensor_time_;
  bool host_time_fallback_;
  bool placed_any_ = false;
  PacketClockConfig clock_config_;
  PacketClock clock_;
  SweepAssembler assembler_;
  DecodedPacket packet_;  // reused between packets
  std::int64_t last_first_ns_ = -1, last_spacing_ns_ = 0, period_ns_ = 0;  // lost_packets
  msg::FiringTable firing_table_;
  runtime::Health health_;
};

}  // namespace adit::drivers
