// A simulated VLP-16 run as the packets a real one would have sent (`adit sim --pcap`, `--lidar-udp`): every firing
// of each sweep goes back into its firing sequence (column from its time, laser from its ring), sequences into
// VLP-16 data packets (drivers::Vlp16PacketEncoder), packets into UDP datagrams from the sensor's factory
// address 192.168.1.201:2368 to 192.168.1.100:2368, sent as the last firing left: into a classic pcap, or live.
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

// The simulated VLP-16's sweeps as the UDP datagrams the sensor would send (payload, time = the packet's last
// firing, the factory addresses and ports), for a capture file or a live link.
class SimVlp16Packets {
 public:
  // Throws std::invalid_argument unless the simulated head is a VLP-16 (`what` names the option in the error).
  SimVlp16Packets(const sim::LidarSimulator& lidar, const std::string& what);

  // One simulated sweep, in publishing order (contiguous sweeps give a contiguous packet stream); the packets
  // it completes, in firing order.
  std::vector<io::UdpDatagram> packetsOf(const LidarScan& scan);

 private:
  const sim::LidarSimulator& lidar_;
  drivers::Vlp16PacketEncoder encoder_;
  std::vector<int> channel_of_ring_;
  std::vector<std::uint8_t> packet_;
};

class SimPcapRecorder {
 public:
  // Throws std::invalid_argument unless the simulated head is a VLP-16.
  SimPcapRecorder(const sim::LidarSimulator& lidar, std::ostream& out);

  // One simulated sweep, in publishing order.
  void addSweep(const LidarScan& scan);
  std::int64_t packets() const { return packets_; }

 private:
  SimVlp16Packets packetizer_;
  io::PcapWriter pcap_;
  std::int64_t packets_ = 0;
};

}  // namespace adit::sources
