// UDP datagrams out of captured frames: the link layer (Ethernet with 802.1Q / 802.1ad VLAN tags, Linux
// cooked SLL and SLL2, raw IP, BSD loopback), IPv4 (header checks, Ethernet padding trimmed by the IP total
// length) and UDP, with IPv4 fragments reassembled. A lidar packet (1206 / 1248 bytes) fits an Ethernet frame,
// but a capture on a host with a small MTU, or of a relay, may hold fragments.
//
// Reassembly memory is bounded: at most kMaxPendingDatagrams datagrams in progress (the oldest is dropped
// when another starts), each at most 64 kB and kMaxFragmentsPerDatagram fragments, and a datagram not
// complete within kFragmentTimeoutNs of capture time after its first fragment is dropped. Overlapping
// fragments are accepted (the later bytes win). Nothing here allocates more than what the frames hold.
// UDP checksums are not verified: a capture taken on the sending host holds checksums the network card
// fills in later, so they are wrong in the file for good packets.
#pragma once

#include "io/capture_file.hpp"

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <vector>

namespace adit::io {

constexpr std::size_t kMaxPendingDatagrams = 64;
constexpr std::size_t kMaxFragmentsPerDatagram = 64;
constexpr std::int64_t kFragmentTimeoutNs = 2000000000;  // 2 s; Linux keeps fragments 30 s, a lidar sends 754/s

struct UdpDatagram {
  std::int64_t time_ns = 0;  // capture time of the frame that completed it
  std::uint32_t src_ip = 0, dst_ip = 0;  // host order, e.g. 192.168.1.201 = 0xC0A801C9
  std::uint16_t src_port = 0, dst_port = 0;
  std::vector<std::uint8_t> payload;
};

class UdpExtractor {
 public:
  // One captured frame; true when it completed a datagram (then in `out`). Anything else is counted.
  bool push(const CapturedFrame& frame, UdpDatagram& out);

  // Named counts: frames, not_ipv4 (ARP, IPv6, ...), not_udp, unknown_link_type, snapped (cut by the snap
  // length before the end of the datagram), bad_ip_header, bad_udp_header, fragments, reassembled,
  // fragments_dropped (timed out, evicted, too many, inconsistent). Only counts > 0 appear.
  const std::map<std::string, std::int64_t>& counters() const { return counters_; }
  // Bytes held by datagrams in reassembly (for the bound's test).
  std::size_t pendingBytes() const;
  std::size_t pendingDatagrams() const { return pending_.size(); }

 private:
  struct Pending {
    std::uint32_t src = 0, dst = 0;
    std::uint16_t id = 0;
    std::int64_t first_ns = 0;
    std::vector<std::uint8_t> bytes;                        // IP payload so far (UDP header first)
    std::vector<std::pair<std::size_t, std::size_t>> have;  // received [begin, end) ranges
    std::size_t total = 0;                                  // known once the last fragment came; 0 = not yet
  };
  bool ipv4(const std::uint8_t* p, std::size_t size, bool snapped, std::int64_t time_ns, UdpDatagram& out);
  bool fragment(const std::uint8_t* header, const std::uint8_t* data, std::size_t size, std::size_t offset,
                bool more, std::int64_t time_ns, UdpDatagram& out);
  bool udp(const std::uint8_t* p, std::size_t size, std::uint32_t src, std::uint32_t dst, std::int64_t time_ns,
           UdpDatagram& out);
  void expire(std::int64_t time_ns);
  void count(const char* name) { counters_[name] += 1; }

  std::deque<Pending> pending_;  // oldest first
  std::map<std::string, std::int64_t> counters_;
};

// Where a link layer's IP packet starts in a frame; false (with a counter name) if the frame carries no IP.
bool ipPayloadOf(const CapturedFrame& frame, std::size_t& offset, const char*& why_not);

// "a.b.c.d" of a host-order IPv4 address.
std::string ipv4ToString(std::uint32_t address);
// Parses "a.b.c.d"; false if it is not one.
bool parseIpv4(const std::string& text, std::uint32_t& address);

}  // namespace adit::io
