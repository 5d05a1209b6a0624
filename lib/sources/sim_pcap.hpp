// A simulated VLP-16 run as the packet capture a real one would have given (`adit sim --pcap`): every firing
// of each sweep goes back into its firing sequence (column from its time, laser from its ring), sequences into
// VLP-16 data packets (drivers::Vlp16PacketEncoder), packets into a classic pcap as UDP datagrams from the
// sensor's factory address 192.168.1.201:2368 to 192.168.1.100:2368, captured as the last firing left.
// The simulated head's timing differs from a real VLP-16 by 14 ns per sequence (1808 columns in exactly
// 0.1 s against 55.296 us sequences): within a packet that is at most 0.3 us, below the stamps' 1 us.
// A tail of fewer than 24 sequences at the end (less than one packet) is not written.
#pragma once

#include "core/types.hpp"
#include "drivers/vlp16_encoder.hpp"
#include "io/capture_writer.hpp"
#include "sim/lidar_model.hpp"

#include <ostream>
#include <vector>

namespace adit::sources {

class SimPcapRecorder {
 public:
  // Throws std::invalid_argument unless the simulated head is a VLP-16.
  SimPcapRecorder(const sim::LidarSimulator& lidar, std::ostream& out);

  // One simulated sweep, in publishing order (contiguous sweeps give a contiguous packet stream).
  void addSweep(const LidarScan& scan);
  std::int64_t packets() const { return packets_; }

 private:
  const sim::LidarSimulator& lidar_;
  io::PcapWriter pcap_;
  drivers::Vlp16PacketEncoder encoder_;
  std::vector<int> channel_of_ring_;
  std::vector<std::uint8_t> packet_;
  std::int64_t packets_ = 0;
};

}  // namespace adit::sources
