// Writes UDP datagrams as a classic pcap file (link type Ethernet, written in little-endian order, microsecond
// or nanosecond stamps), as tcpdump would have captured them on the receiving host: Ethernet II, IPv4 (header
// checksum filled in, fragmented at the MTU like the sender's IP stack), UDP (checksum 0 = none, allowed over
// IPv4). For `adit sim --pcap` and the tests of the capture reader.
#pragma once

#include "io/udp_capture.hpp"

#include <cstdint>
#include <ostream>
#include <vector>

namespace adit::io {

// The IPv4 packets that carry `datagram` (its payload, addresses and ports), fragmented so that none is larger
// than `mtu` bytes (one packet when it fits). `ip_id` identifies the datagram's fragments.
std::vector<std::vector<std::uint8_t>> ipv4UdpPackets(const UdpDatagram& datagram, std::uint16_t ip_id,
                                                      std::size_t mtu = 1500);
// An Ethernet II frame around an IPv4 packet (made-up MAC addresses).
std::vector<std::uint8_t> ethernetFrame(const std::vector<std::uint8_t>& ip_packet);

class PcapWriter {
 public:
  // Writes the file header now. snap_length: recorded in the header (records are written whole).
  explicit PcapWriter(std::ostream& out, bool nanoseconds = false, std::uint32_t link_type = kLinkEthernet);

  // One record: `frame` captured at time_ns; original_length > frame.size() marks it cut by a snap length.
  void writeFrame(std::int64_t time_ns, const std::vector<std::uint8_t>& frame, std::uint32_t original_length = 0);
  // A UDP datagram as Ethernet frames (fragments all stamped time_ns); returns the number of frames.
  std::size_t writeUdp(const UdpDatagram& datagram, std::size_t mtu = 1500);

 private:
  std::ostream& out_;
  bool nanoseconds_;
  std::uint16_t next_id_ = 1;
};

}  // namespace adit::io
