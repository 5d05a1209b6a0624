// Packet capture files as tcpdump and Wireshark write them, read record by record without libpcap:
//  - classic pcap: 24-byte file header (magic a1b2c3d4 = microsecond or a1b23c4d = nanosecond stamps, in
//    either byte order; version; snap length; link type), then per packet a 16-byte record header (seconds,
//    fraction, captured length, original length) and the captured bytes;
//  - pcapng: blocks of (type, total length, body, total length). Section Header Blocks set the byte order
//    (magic 1a2b3c4d) and restart the interface list; Interface Description Blocks give each interface's
//    link type, snap length and timestamp resolution (option if_tsresol) and offset (if_tsoffset);
//    Enhanced and Simple Packet Blocks (and the obsolete Packet Block) carry packets; any other block is
//    skipped by its length.
// Damage is never fatal to the process: a record cut short by the end of the file, a record length beyond
// any plausible packet or a block whose lengths disagree ends the reading (counted), since the rest of the
// file cannot be found again reliably; a packet of an unknown interface is skipped (counted).
#pragma once

#include <cstdint>
#include <istream>
#include <map>
#include <string>
#include <vector>

namespace adit::io {

// Link-layer header types (tcpdump.org/linktypes.html) this project reads.
constexpr std::uint32_t kLinkNull = 0;        // BSD loopback: 4-byte address family in the writer's byte order
constexpr std::uint32_t kLinkEthernet = 1;    // Ethernet II, with 802.1Q / 802.1ad VLAN tags
constexpr std::uint32_t kLinkRaw = 101;       // raw IP (also 12 and 14 on some systems)
constexpr std::uint32_t kLinkLinuxSll = 113;  // Linux "cooked" capture v1 (tcpdump -i any)
constexpr std::uint32_t kLinkIpv4 = 228;      // raw IPv4
constexpr std::uint32_t kLinkLinuxSll2 = 276; // Linux "cooked" capture v2

// Largest record accepted: far above any Ethernet frame (jumbo 9 kB) or a loopback's 64 kB; a larger
// length means the file is corrupt and is not allocated.
constexpr std::uint32_t kMaxCaptureRecordBytes = 256 * 1024;

struct CapturedFrame {
  std::uint32_t link_type = 0;
  std::int64_t time_ns = 0;           // capture time, ns since 1970
  std::uint32_t original_length = 0;  // length on the wire
  std::vector<std::uint8_t> bytes;    // what was captured (shorter than original_length when snapped)
};

class CaptureReader {
 public:
  // `name` only appears in messages. Throws ReadError if the stream does not start like a pcap or pcapng file.
  CaptureReader(std::istream& in, std::string name);

  // The next packet record; false at the end of the file or at damage that ends the reading.
  bool next(CapturedFrame& frame);

  bool isPcapng() const { return pcapng_; }
  // Named counts of what was skipped: truncated_record, corrupt_record, unknown_interface, bad_timestamp_resolution,
  // skipped_block. Only counts > 0 appear.
  const std::map<std::string, std::int64_t>& counters() const { return counters_; }
  // The last damage seen, one line naming the file ("" if none).
  const std::string& lastError() const { return last_error_; }

 private:
  struct Interface {
    std::uint32_t link_type = 0;
    std::uint32_t snap_length = 0;
    bool binary_resolution = false;  // if_tsresol: 2^-exponent s units instead of 10^-exponent
    int exponent = 6;                // default: microseconds
    std::int64_t offset_s = 0;       // if_tsoffset
  };
  bool nextClassic(CapturedFrame& frame);
  bool nextPcapng(CapturedFrame& frame);
  bool readSectionHeader(const std::vector<std::uint8_t>& body);
  void readInterface(const std::vector<std::uint8_t>& body);
  bool packetFromBlock(std::uint32_t type, const std::vector<std::uint8_t>& body, CapturedFrame& frame);
  bool readExact(std::uint8_t* out, std::size_t n);
  bool readAppending(std::vector<std::uint8_t>& out, std::size_t n);
  std::uint16_t u16(const std::uint8_t* p) const;
  std::uint32_t u32(const std::uint8_t* p) const;
  void damage(const std::string& counter, const std::string& what);

  std::istream& in_;
  std::string name_;
  bool pcapng_ = false;
  bool swapped_ = false;  // file byte order is big-endian
  bool ended_ = false;
  // classic pcap
  std::uint32_t classic_link_ = 0;
  bool classic_nanos_ = false;
  // pcapng
  std::vector<Interface> interfaces_;
  std::int64_t last_time_ns_ = 0;  // Simple Packet Blocks have no stamp: they take the previous packet's
  std::map<std::string, std::int64_t> counters_;
  std::string last_error_;
  std::int64_t records_ = 0;
};

// Capture time in ns of a stamp counted in units of 10^-exponent s (binary: 2^-exponent s).
std::int64_t captureTimeNs(std::uint64_t stamp, int exponent, bool binary);

}  // namespace adit::io
