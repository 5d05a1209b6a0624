#include "io/capture_writer.hpp"

#include <algorithm>
#include <stdexcept>

namespace adit::io {
namespace {

void putBe16(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}
void putBe32(std::uint8_t* p, std::uint32_t v) {
  putBe16(p, v >> 16);
  putBe16(p + 2, v & 0xFFFF);
}
void putLe32(std::ostream& out, std::uint32_t v) {
  const char b[4] = {static_cast<char>(v & 0xFF), static_cast<char>((v >> 8) & 0xFF), static_cast<char>((v >> 16) & 0xFF),
                     static_cast<char>(v >> 24)};
  out.write(b, 4);
}

// RFC 791 header checksum: one's complement of the one's-complement sum of the header's 16-bit words.
std::uint16_t ipChecksum(const std::uint8_t* header, std::size_t size) {
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i + 1 < size; i += 2) sum += static_cast<std::uint32_t>((header[i] << 8) | header[i + 1]);
  while (sum >> 16) sum = (sum & 0xFFFF) + (sum >> 16);
  return static_cast<std::uint16_t>(~sum & 0xFFFF);
}

}  // namespace

std::vector<std::vector<std::uint8_t>> ipv4UdpPackets(const UdpDatagram& d, std::uint16_t ip_id, std::size_t mtu) {
  if (d.payload.size() > 65507) throw std::invalid_argument("UDP payload larger than an IPv4 datagram");
  std::vector<std::uint8_t> udp(8 + d.payload.size());
  putBe16(udp.data(), d.src_port);
  putBe16(udp.data() + 2, d.dst_port);
  putBe16(udp.data() + 4, static_cast<std::uint32_t>(udp.size()));
  std::copy(d.payload.begin(), d.payload.end(), udp.begin() + 8);
  // Each fragment but the last carries a multiple of 8 bytes (the offset field counts 8-byte units).
  const std::size_t step = mtu > 28 ? ((mtu - 20) / 8) * 8 : 8;
  std::vector<std::vector<std::uint8_t>> packets;
  for (std::size_t at = 0; at < udp.size(); at += step) {
    const std::size_t n = std::min(step, udp.size() - at);
    const bool more = at + n < udp.size();
    std::vector<std::uint8_t> p(20 + n);
    p[0] = 0x45;  // version 4, 20-byte header
    putBe16(p.data() + 2, static_cast<std::uint32_t>(p.size()));
    putBe16(p.data() + 4, ip_id);
    putBe16(p.data() + 6, (more ? 0x2000u : 0u) | static_cast<std::uint32_t>(at / 8));
    p[8] = 64;  // TTL
    p[9] = 17;  // UDP
    putBe32(p.data() + 12, d.src_ip);
    putBe32(p.data() + 16, d.dst_ip);
    putBe16(p.data() + 10, ipChecksum(p.data(), 20));
    std::copy(udp.begin() + static_cast<std::ptrdiff_t>(at), udp.begin() + static_cast<std::ptrdiff_t>(at + n),
              p.begin() + 20);
    packets.push_back(std::move(p));
  }
  return packets;
}

std::vector<std::uint8_t> ethernetFrame(const std::vector<std::uint8_t>& ip_packet) {
  // Destination: the host; source: a Velodyne-style MAC (60:76:88 is Velodyne's OUI).
  static constexpr std::uint8_t kHeader[14] = {0x00, 0x1B, 0x21, 0x00, 0x00, 0x01, 0x60,
                                                0x76, 0x88, 0x00, 0x00, 0x02, 0x08, 0x00};
  std::vector<std::uint8_t> f(sizeof kHeader + ip_packet.size());
  std::copy(kHeader, kHeader + sizeof kHeader, f.begin());
  std::copy(ip_packet.begin(), ip_packet.end(), f.begin() + sizeof kHeader);
  return f;
}

PcapWriter::PcapWriter(std::ostream& out, bool nanoseconds, std::uint32_t link_type)
    : out_(out), nanoseconds_(nanoseconds) {
  putLe32(out_, nanoseconds ? 0xA1B23C4D : 0xA1B2C3D4);
  putLe32(out_, 2 | (4u << 16));  // version 2.4
  putLe32(out_, 0);               // time zone
  putLe32(out_, 0);               // accuracy
  putLe32(out_, 262144);          // snap length
  putLe32(out_, link_type);
}

void PcapWriter::writeFrame(std::int64_t time_ns, const std::vector<std::uint8_t>& frame, std::uint32_t original_length) {
  const std::int64_t seconds = time_ns / 1000000000, rest = time_ns % 1000000000;
  putLe32(out_, static_cast<std::uint32_t>(seconds));
  putLe32(out_, static_cast<std::uint32_t>(nanoseconds_ ? rest : rest / 1000));
  putLe32(out_, static_cast<std::uint32_t>(frame.size()));
  putLe32(out_, std::max(original_length, static_cast<std::uint32_t>(frame.size())));
  out_.write(reinterpret_cast<const char*>(frame.data()), static_cast<std::streamsize>(frame.size()));
}

std::size_t PcapWriter::writeUdp(const UdpDatagram& datagram, std::size_t mtu) {
  const auto packets = ipv4UdpPackets(datagram, next_id_++, mtu);
  for (const auto& p : packets) writeFrame(datagram.time_ns, ethernetFrame(p));
  return packets.size();
}

}  // namespace adit::io
