// The capture reader and UDP extraction against files built byte by byte here (from the pcap and pcapng
// specifications, independently of io::PcapWriter): both byte orders, micro/nanosecond and binary stamp
// resolutions, every link type read, and damaged input: truncated records, snapped frames, wrong lengths,
// garbage, fragment floods. Damage is counted, never thrown past the file header, never a hang.
#include "io/capture_file.hpp"
#include "io/capture_writer.hpp"
#include "io/io_error.hpp"
#include "io/udp_capture.hpp"

#include <gtest/gtest.h>

#include <random>
#include <sstream>

namespace adit::io {
namespace {

// Appends integers in a chosen byte order.
struct Bytes {
  bool big = false;
  std::string s = {};
  Bytes& u8(unsigned v) {
    s.push_back(static_cast<char>(v & 0xFF));
    return *this;
  }
  Bytes& u16(unsigned v) { return big ? u8(v >> 8).u8(v) : u8(v).u8(v >> 8); }
  Bytes& u32(std::uint32_t v) { return big ? u16(v >> 16).u16(v & 0xFFFF) : u16(v & 0xFFFF).u16(v >> 16); }
  Bytes& raw(const std::vector<std::uint8_t>& b) {
    s.append(b.begin(), b.end());
    return *this;
  }
  Bytes& pad4() {
    while (s.size() % 4) u8(0);
    return *this;
  }
};

UdpDatagram sample(std::size_t size, std::uint16_t port = 2368) {
  UdpDatagram d;
  d.src_ip = 0xC0A801C9;
  d.dst_ip = 0xC0A80164;
  d.src_port = port;
  d.dst_port = port;
  for (std::size_t i = 0; i < size; ++i) d.payload.push_back(static_cast<std::uint8_t>(i * 7 + 3));
  return d;
}
std::vector<std::uint8_t> ipPacket(std::size_t size) { return ipv4UdpPackets(sample(size), 9).at(0); }

// A pcapng block: type, total length, body (padded), total length.
void block(Bytes& out, std::uint32_t type, const std::string& body) {
  Bytes b{out.big, body};
  b.pad4();
  out.u32(type).u32(static_cast<std::uint32_t>(b.s.size() + 12));
  out.s += b.s;
  out.u32(static_cast<std::uint32_t>(b.s.size() + 12));
}
void sectionHeader(Bytes& out) {
  Bytes b{out.big};
  b.u32(0x1A2B3C4D).u16(1).u16(0).u32(0xFFFFFFFF).u32(0xFFFFFFFF);
  block(out, 0x0A0D0D0A, b.s);
}
void interface(Bytes& out, std::uint16_t link, int tsresol = -1) {
  Bytes b{out.big};
  b.u16(link).u16(0).u32(65535);
  if (tsresol >= 0) b.u16(9).u16(1).u8(static_cast<unsigned>(tsresol)).pad4();
  b.u16(0).u16(0);
  block(out, 1, b.s);
}
void enhancedPacket(Bytes& out, std::uint32_t itf, std::uint64_t stamp, const std::vector<std::uint8_t>& data) {
  Bytes b{out.big};
  b.u32(itf).u32(static_cast<std::uint32_t>(stamp >> 32)).u32(static_cast<std::uint32_t>(stamp));
  b.u32(static_cast<std::uint32_t>(data.size())).u32(static_cast<std::uint32_t>(data.size())).raw(data);
  block(out, 6, b.s);
}

std::vector<UdpDatagram> readAll(const std::string& bytes, std::map<std::string, std::int64_t>* counters = nullptr) {
  std::istringstream in(bytes);
  CaptureReader reader(in, "t");
  UdpExtractor udp;
  CapturedFrame f;
  UdpDatagram d;
  std::vector<UdpDatagram> out;
  while (reader.next(f))
    if (udp.push(f, d)) out.push_back(d);
  if (counters) {
    *counters = reader.counters();
    for (const auto& [k, v] : udp.counters()) (*counters)[k] += v;
  }
  return out;
}

std::vector<std::uint8_t> sll2(const std::vector<std::uint8_t>& ip) {
  std::vector<std::uint8_t> f = {0x08, 0x00, 0, 0, 0, 0, 0, 2, 0, 1, 0, 6, 0x60, 0x76, 0x88, 0, 0, 2, 0, 0};
  f.insert(f.end(), ip.begin(), ip.end());
  return f;
}
std::vector<std::uint8_t> sll(const std::vector<std::uint8_t>& ip) {
  std::vector<std::uint8_t> f = {0, 0, 0, 1, 0, 6, 0x60, 0x76, 0x88, 0, 0, 2, 0, 0, 0x08, 0x00};
  f.insert(f.end(), ip.begin(), ip.end());
  return f;
}
std::vector<std::uint8_t> vlanEthernet(const std::vector<std::uint8_t>& ip) {
  std::vector<std::uint8_t> f = ethernetFrame(ip);
  // 802.1ad outer tag, 802.1Q inner tag, then IPv4.
  const std::vector<std::uint8_t> tags = {0x88, 0xA8, 0x00, 0x05, 0x81, 0x00, 0x00, 0x07};
  f.insert(f.begin() + 12, tags.begin(), tags.end());
  return f;
}

TEST(Pcapng, BigEndianSectionWithThreeInterfacesAndResolutions) {
  for (const bool big : {false, true}) {
    Bytes out{big};
    sectionHeader(out);
    interface(out, kLinkLinuxSll2, 9);      // nanoseconds
    interface(out, kLinkEthernet);          // default: microseconds
    interface(out, kLinkIpv4, 0x80 | 20);   // 2^-20 s
    block(out, 5, std::string(20, 'x'));    // an Interface Statistics Block: skipped
    enhancedPacket(out, 0, 1700000000123456789ULL, sll2(ipPacket(1206)));
    enhancedPacket(out, 1, 1700000000123456ULL, vlanEthernet(ipPacket(1206)));
    enhancedPacket(out, 2, (1700000000ULL << 20) | (1 << 19), ipPacket(1206));  // .5 s
    {
      Bytes spb{big};  // a Simple Packet Block: interface 0, no stamp
      const auto frame = sll2(ipPacket(100));
      spb.u32(static_cast<std::uint32_t>(frame.size())).raw(frame);
      block(out, 3, spb.s);
    }
    std::map<std::string, std::int64_t> counters;
    const auto got = readAll(out.s, &counters);
    ASSERT_EQ(got.size(), 4u) << (big ? "big-endian" : "little-endian");
    EXPECT_EQ(got[0].time_ns, 1700000000123456789LL);
    EXPECT_EQ(got[1].time_ns, 1700000000123456000LL);
    EXPECT_EQ(got[2].time_ns, 1700000000500000000LL);
    EXPECT_EQ(got[3].time_ns, got[2].time_ns);  // no stamp: the previous packet's
    for (int i = 0; i < 3; ++i) EXPECT_EQ(got[static_cast<std::size_t>(i)].payload, sample(1206).payload);
    EXPECT_EQ(got[3].payload, sample(100).payload);
    EXPECT_EQ(got[0].src_ip, 0xC0A801C9u);
    EXPECT_EQ(got[0].dst_port, 2368);
    EXPECT_EQ(counters["skipped_block"], 1);
  }
}

TEST(Pcapng, PacketOfAnUndescribedInterfaceIsCounted) {
  Bytes out;
  sectionHeader(out);
  interface(out, kLinkEthernet);
  enhancedPacket(out, 3, 1, ethernetFrame(ipPacket(10)));
  enhancedPacket(out, 0, 1, ethernetFrame(ipPacket(10)));
  std::map<std::string, std::int64_t> counters;
  EXPECT_EQ(readAll(out.s, &counters).size(), 1u);
  EXPECT_EQ(counters["unknown_interface"], 1);
}

// Classic pcap header and records built by hand, in either byte order.
std::string classic(bool big, bool nanos, std::uint32_t link, const std::vector<std::vector<std::uint8_t>>& frames,
                    std::uint32_t snap = 65535) {
  Bytes out{big};
  out.u32(nanos ? 0xA1B23C4D : 0xA1B2C3D4).u16(2).u16(4).u32(0).u32(0).u32(snap).u32(link);
  std::uint32_t us = 250;
  for (const auto& f : frames) {
    const std::uint32_t captured = std::min<std::uint32_t>(snap, static_cast<std::uint32_t>(f.size()));
    out.u32(1700000000).u32(nanos ? us * 1000 : us).u32(captured).u32(static_cast<std::uint32_t>(f.size()));
    out.s.append(f.begin(), f.begin() + captured);
    ++us;
  }
  return out.s;
}

TEST(ClassicPcap, BothByteOrdersBothResolutionsEveryLinkType) {
  const auto ip = ipPacket(1248);
  struct Link {
    std::uint32_t type;
    std::vector<std::uint8_t> frame;
  };
  std::vector<std::uint8_t> null_frame = {2, 0, 0, 0};
  null_frame.insert(null_frame.end(), ip.begin(), ip.end());
  const std::vector<Link> links = {{kLinkEthernet, ethernetFrame(ip)}, {kLinkEthernet, vlanEthernet(ip)},
                                   {kLinkLinuxSll, sll(ip)},           {kLinkLinuxSll2, sll2(ip)},
                                   {kLinkRaw, ip},                     {kLinkIpv4, ip},
                                   {kLinkNull, null_frame}};
  for (const bool big : {false, true})
    for (const bool nanos : {false, true})
      for (const Link& link : links) {
        const auto got = readAll(classic(big, nanos, link.type, {link.frame, link.frame}));
        ASSERT_EQ(got.size(), 2u) << "link " << link.type << (big ? " big" : " little") << (nanos ? " ns" : " us");
        EXPECT_EQ(got[1].time_ns, 1700000000LL * 1000000000 + 251000);
        EXPECT_EQ(got[1].payload, sample(1248).payload);
      }
}

TEST(ClassicPcap, EthernetPaddingIsTrimmedByTheIpLength) {
  auto frame = ethernetFrame(ipPacket(2));  // 14 + 30 bytes: padded to Ethernet's 60-byte minimum
  frame.resize(60, 0);
  const auto got = readAll(classic(false, false, kLinkEthernet, {frame}));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].payload.size(), 2u);
}

TEST(BadCapture, NotACaptureIsAReadError) {
  EXPECT_THROW(readAll(""), ReadError);
  EXPECT_THROW(readAll("ab"), ReadError);
  EXPECT_THROW(readAll("hello, this is a text file\n"), ReadError);
  EXPECT_THROW(readAll(std::string("\xD4\xC3\xB2\xA1", 4) + "short"), ReadError);
}

TEST(BadCapture, TruncatedLastRecordKeepsWhatCameBefore) {
  const auto frame = ethernetFrame(ipPacket(1206));
  const std::string whole = classic(false, false, kLinkEthernet, {frame, frame, frame});
  for (const std::size_t cut : {std::size_t{5}, std::size_t{16}, std::size_t{200}, frame.size() + 15}) {
    std::map<std::string, std::int64_t> counters;
    const auto got = readAll(whole.substr(0, whole.size() - cut), &counters);
    EXPECT_EQ(got.size(), 2u) << "cut " << cut;
    EXPECT_EQ(counters["truncated_record"], 1) << "cut " << cut;
  }
}

TEST(BadCapture, SnapLengthShorterThanThePacketIsCounted) {
  const auto frame = ethernetFrame(ipPacket(1206));
  std::map<std::string, std::int64_t> counters;
  EXPECT_TRUE(readAll(classic(false, false, kLinkEthernet, {frame, frame}, 96), &counters).empty());
  EXPECT_EQ(counters["snapped"], 2);
}

TEST(BadCapture, ImplausibleRecordLengthEndsTheReadingWithoutAllocating) {
  Bytes out;
  out.u32(0xA1B2C3D4).u16(2).u16(4).u32(0).u32(0).u32(65535).u32(1);
  out.u32(0).u32(0).u32(0xFFFFFFF0).u32(0xFFFFFFF0);
  std::map<std::string, std::int64_t> counters;
  EXPECT_TRUE(readAll(out.s, &counters).empty());
  EXPECT_EQ(counters["corrupt_record"], 1);
}

TEST(BadCapture, LyingIpAndUdpLengthsAreCounted) {
  auto long_ip = ipPacket(100);
  long_ip[2] = 0x10;  // IP total length 4096+ > the frame
  auto short_udp = ipPacket(100);
  short_udp[20 + 4] = 0;
  short_udp[20 + 5] = 4;  // UDP length 4 < its header
  auto tcp = ipPacket(100);
  tcp[9] = 6;
  auto ipv6 = ipPacket(100);
  ipv6[0] = 0x60;
  std::map<std::string, std::int64_t> counters;
  EXPECT_TRUE(readAll(classic(false, false, kLinkRaw, {long_ip, short_udp, tcp, ipv6, {0x45}}), &counters).empty());
  EXPECT_EQ(counters["bad_ip_header"], 2);
  EXPECT_EQ(counters["bad_udp_header"], 1);
  EXPECT_EQ(counters["not_udp"], 1);
  EXPECT_EQ(counters["not_ipv4"], 1);
}

TEST(BadCapture, PcapngBlockLengthsThatDisagreeEndTheReading) {
  Bytes out;
  sectionHeader(out);
  interface(out, kLinkRaw);
  enhancedPacket(out, 0, 5, ipPacket(10));
  Bytes bad;
  enhancedPacket(bad, 0, 6, ipPacket(10));
  bad.s[bad.s.size() - 1] ^= 0x40;  // trailing length differs
  std::map<std::string, std::int64_t> counters;
  EXPECT_EQ(readAll(out.s + bad.s + out.s.substr(out.s.size() - 40), &counters).size(), 1u);
  EXPECT_EQ(counters["corrupt_record"], 1);
}

// Every prefix and many random corruptions of a small valid file: a ReadError for a header that is not one,
// otherwise a clean end; never another exception, never a hang.
TEST(BadCapture, EveryPrefixAndRandomCorruptionEndsCleanly) {
  Bytes ng;
  sectionHeader(ng);
  interface(ng, kLinkEthernet, 9);
  for (int i = 0; i < 3; ++i) enhancedPacket(ng, 0, 1000 + i, ethernetFrame(ipPacket(300)));
  const auto frame = ethernetFrame(ipPacket(300));
  const std::vector<std::string> files = {classic(true, true, kLinkEthernet, {frame, frame, frame}), ng.s};
  std::mt19937 rng(7);
  for (const std::string& file : files) {
    for (std::size_t n = 0; n <= file.size(); ++n) {
      try {
        readAll(file.substr(0, n));
      } catch (const ReadError&) {
        EXPECT_LT(n, 40u);
      }
    }
    for (int trial = 0; trial < 3000; ++trial) {
      std::string bad = file;
      for (int k = 0; k < 4; ++k) bad[rng() % bad.size()] = static_cast<char>(rng());
      try {
        readAll(bad);
      } catch (const ReadError&) {
      }
    }
  }
}

TEST(Fragments, ReassembledInAnyOrderWithOverlap) {
  const UdpDatagram d = sample(3000);
  auto fragments = ipv4UdpPackets(d, 77, 576);
  ASSERT_EQ(fragments.size(), 6u);
  std::swap(fragments[0], fragments[4]);
  fragments.push_back(fragments[2]);  // a duplicate
  const auto got = readAll(classic(false, false, kLinkRaw, fragments));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].payload, d.payload);
}

TEST(Fragments, MemoryStaysBoundedUnderAFloodOfIncompleteDatagrams) {
  UdpExtractor udp;
  UdpDatagram out;
  CapturedFrame f;
  f.link_type = kLinkRaw;
  // Only the last fragment of a 60 kB datagram, under 5000 ids: none can ever complete.
  const std::vector<std::uint8_t> last = ipv4UdpPackets(sample(60000), 0, 1500).back();
  for (int i = 0; i < 5000; ++i) {
    f.bytes = last;
    f.bytes[4] = static_cast<std::uint8_t>(i >> 8);
    f.bytes[5] = static_cast<std::uint8_t>(i);
    f.original_length = static_cast<std::uint32_t>(f.bytes.size());
    f.time_ns = i;
    EXPECT_FALSE(udp.push(f, out));
    ASSERT_LE(udp.pendingDatagrams(), kMaxPendingDatagrams);
  }
  EXPECT_LE(udp.pendingBytes(), kMaxPendingDatagrams * 65535);
  EXPECT_EQ(udp.counters().at("fragments_dropped"), 5000 - static_cast<std::int64_t>(kMaxPendingDatagrams));
  // Two seconds later of capture time every stale datagram is gone.
  auto frags = ipv4UdpPackets(sample(2000), 1, 1500);
  f.time_ns = 5000 + kFragmentTimeoutNs + 1;
  f.bytes = frags[0];
  f.original_length = static_cast<std::uint32_t>(f.bytes.size());
  EXPECT_FALSE(udp.push(f, out));
  EXPECT_EQ(udp.pendingDatagrams(), 1u);
  f.bytes = frags[1];
  f.original_length = static_cast<std::uint32_t>(f.bytes.size());
  ASSERT_TRUE(udp.push(f, out));
  EXPECT_EQ(out.payload, sample(2000).payload);
}

TEST(Fragments, BeyondSixtyFourKilobytesIsDropped) {
  auto frag = ipv4UdpPackets(sample(100), 3, 1500)[0];
  frag[6] = 0x3F;  // more fragments, offset 0x1FFF * 8 = 65528: with 108 bytes beyond 65535
  frag[7] = 0xFF;
  std::map<std::string, std::int64_t> counters;
  EXPECT_TRUE(readAll(classic(false, false, kLinkRaw, {frag}), &counters).empty());
  EXPECT_EQ(counters["fragments_dropped"], 1);
}

TEST(TimeResolution, DecimalAndBinaryUnits) {
  EXPECT_EQ(captureTimeNs(1500000, 6, false), 1500000000);
  EXPECT_EQ(captureTimeNs(123456789, 9, false), 123456789);
  EXPECT_EQ(captureTimeNs(123456789012ULL, 12, false), 123456789);
  EXPECT_EQ(captureTimeNs(3, 0, false), 3000000000);
  EXPECT_EQ(captureTimeNs(3ULL << 32 | (1ULL << 31), 32, true), 3500000000);
  EXPECT_EQ(captureTimeNs(~0ULL, 0, false), std::numeric_limits<std::int64_t>::max());  // saturates
  EXPECT_GE(captureTimeNs(~0ULL, 63, true), 0);
}

}  // namespace
}  // namespace adit::io
