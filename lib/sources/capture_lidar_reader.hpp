// The sweeps of a recorded capture (pcap / pcapng) of a VLP-16 or RS-16: the capture's UDP datagrams to the
// sensor's data port go through the same LidarPacketStream (decoders, packet clock, sweep assembler) as the
// live driver, with each packet's capture time in place of the kernel receive time, so a recording gives the
// sweeps the live bridge would have published. Pure: a stream in, sweeps out (no clock).
//
// Time: the packets' own stamps (time_source sensor), anchored at the capture time of the first packet; if
// the sensor's stamps are unusable (an RS-16 whose clock was never set) the capture times are used instead
// (counter host_time_fallback); time_source host uses the capture times throughout.
// Filtering: datagrams to another port (other_port) or from another host than the sensor (other_host) are
// skipped and counted; the sensor is lidar_driver.sensor_address, or else the first host that sent a packet of
// the model's size to the data port. At the end of the capture the sweep in progress is published flagged partial.
// Damage in the file (truncated or corrupt records, cut frames, lost fragments) is counted and skipped.
// Reordering: the data packets pass a window of kReorderWindow packets that releases them in the order of their
// own stamps (counter reordered), so a packet captured up to that many places late is still used; one later than
// that is counted as time_backwards and skipped, as live.
// RS-16: DIFOP packets (lidar_driver.difop_port, default 7788) set the return mode and calibrated angles.
#pragma once

#include "drivers/lidar_stream.hpp"
#include "drivers/udp_lidar_source.hpp"
#include "io/capture_file.hpp"
#include "io/udp_capture.hpp"
#include "runtime/health.hpp"

#include <deque>
#include <istream>
#include <map>
#include <string>
#include <vector>

namespace adit::sources {

constexpr std::size_t kReorderWindow = 8;

class CaptureLidarReader {
 public:
  // Throws io::ReadError if `in` is not a capture, std::invalid_argument on a bad config.
  CaptureLidarReader(std::istream& in, std::string name, const drivers::UdpLidarConfig& config);

  // Reads packets until at least one sweep is appended to `sweeps` or the capture ends; false when there is
  // nothing more (the final partial sweep has been appended before).
  bool read(std::vector<LidarScan>& sweeps);

  // inputs = lidar packets, outputs = sweeps; the stream's counters plus the file's and the network's.
  runtime::Health health() const;
  const msg::FiringTable& firingTable() const { return stream_.firingTable(); }
  // One line of what the capture held (frames, packets, sweeps, every counter), for the end of an import.
  std::string summary() const;

 private:
  void hold(std::vector<LidarScan>& sweeps);
  void release(std::vector<LidarScan>& sweeps);

  struct Held {
    std::int64_t key;  // stamp key, unwrapped against the last released packet
    io::UdpDatagram datagram;
  };
  std::string name_;
  drivers::LidarModel model_;
  std::deque<Held> window_;  // sorted by key
  bool have_reference_ = false;
  std::int64_t reference_key_ = 0;
  io::CaptureReader reader_;
  io::UdpExtractor extractor_;
  drivers::LidarPacketStream stream_;
  std::uint16_t port_;
  int difop_port_ = -1;  // RS-16: DIFOP datagrams go to the stream; -1 = none
  bool have_sensor_ = false;
  std::uint32_t sensor_ip_ = 0;
  bool finished_ = false;
  io::CapturedFrame frame_;
  io::UdpDatagram datagram_;
  std::map<std::string, std::int64_t> counters_;
};

}  // namespace adit::sources
