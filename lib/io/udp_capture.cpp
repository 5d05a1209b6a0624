#include "io/udp_capture.hpp"

#include <algorithm>
#include <cstdio>

namespace adit::io {
namespace {

constexpr std::uint16_t kEtherIpv4 = 0x0800;
constexpr std::size_t kMaxIpDatagram = 65535;

std::uint16_t be16(const std::uint8_t* p) { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }
std::uint32_t be32(const std::uint8_t* p) {
  return (static_cast<std::uint32_t>(p[0]) << 24) | (static_cast<std::uint32_t>(p[1]) << 16) |
         (static_cast<std::uint32_t>(p[2]) << 8) | p[3];
}

bool ethernetPayload(const std::vector<std::uint8_t>& f, std::size_t& offset, const char*& why_not) {
  if (f.size() < 14) {
    why_not = "snapped";
    return false;
  }
  std::uint16_t type = be16(f.data() + 12);
  offset = 14;
  // 802.1Q, 802.1ad and the older 0x9100 QinQ tag: 4 bytes each (TCI, then the inner type); two at most.
  for (int tags = 0; tags < 2 && (type == 0x8100 || type == 0x88A8 || type == 0x9100); ++tags) {
    if (f.size() < offset + 4) {
      why_not = "snapped";
      return false;
    }
    type = be16(f.data() + offset + 2);
    offset += 4;
  }
  if (type != kEtherIpv4) {
    why_not = "not_ipv4";
    return false;
  }
  return true;
}

}  // namespace

bool ipPayloadOf(const CapturedFrame& frame, std::size_t& offset, const char*& why_not) {
  const std::vector<std::uint8_t>& f = frame.bytes;
  offset = 0;
  switch (frame.link_type) {
    case kLinkEthernet:
      return ethernetPayload(f, offset, why_not);
    case kLinkLinuxSll:  // packet type, ARPHRD type, address length, 8 address bytes, protocol
    case kLinkLinuxSll2: {  // protocol, reserved, interface index, ARPHRD type, packet type, length, 8 address bytes
      const bool v2 = frame.link_type == kLinkLinuxSll2;
      const std::size_t header = v2 ? 20 : 16;
      if (f.size() < header) {
        why_not = "snapped";
        return false;
      }
      if (be16(f.data() + (v2 ? 0 : 14)) != kEtherIpv4) {
        why_not = "not_ipv4";
        return false;
      }
      offset = header;
      return true;
    }
    case kLinkNull: {  // AF_INET (2) in the writing host's byte order
      if (f.size() < 4) {
        why_not = "snapped";
        return false;
      }
      const bool inet = (f[0] == 2 && f[1] == 0 && f[2] == 0 && f[3] == 0) || (f[0] == 0 && f[1] == 0 && f[2] == 0 && f[3] == 2);
      if (!inet) {
        why_not = "not_ipv4";
        return false;
      }
      offset = 4;
      return true;
    }
    case kLinkRaw:
    case 12:
    case 14:
    case kLinkIpv4:
      return true;  // the IP version is checked by the IPv4 parser
    default:
      why_not = "unknown_link_type";
      return false;
  }
}

bool UdpExtractor::push(const CapturedFrame& frame, UdpDatagram& out) {
  count("frames");
  std::size_t offset = 0;
  const char* why_not = "";
  if (!ipPayloadOf(frame, offset, why_not)) {
    count(why_not);
    return false;
  }
  const bool snapped = frame.original_length > frame.bytes.size();
  return ipv4(frame.bytes.data() + offset, frame.bytes.size() - offset, snapped, frame.time_ns, out);
}

bool UdpExtractor::ipv4(const std::uint8_t* p, std::size_t size, bool snapped, std::int64_t time_ns,
                        UdpDatagram& out) {
  if (size >= 1 && (p[0] >> 4) != 4) {
    count("not_ipv4");
    return false;
  }
  const std::size_t header = size >= 1 ? static_cast<std::size_t>(p[0] & 0x0F) * 4 : 0;
  if (size < 20 || size < header) {
    count(snapped ? "snapped" : "bad_ip_header");
    return false;
  }
  const std::size_t total = be16(p + 2);
  if (header < 20 || total < header) {
    count("bad_ip_header");
    return false;
  }
  if (total > size) {  // the rest was not captured (snap length) or the frame lies about its length
    count(snapped ? "snapped" : "bad_ip_header");
    return false;
  }
  if (p[9] != 17) {
    count("not_udp");
    return false;
  }
  const std::uint32_t src = be32(p + 12), dst = be32(p + 16);
  const std::uint16_t flags = be16(p + 6);
  const bool more = (flags & 0x2000) != 0;
  const std::size_t frag_offset = static_cast<std::size_t>(flags & 0x1FFF) * 8;
  if (more || frag_offset > 0) return fragment(p, p + header, total - header, frag_offset, more, time_ns, out);
  return udp(p + header, total - header, src, dst, time_ns, out);
}

bool UdpExtractor::udp(const std::uint8_t* p, std::size_t size, std::uint32_t src, std::uint32_t dst,
                       std::int64_t time_ns, UdpDatagram& out) {
  if (size < 8) {
    count("bad_udp_header");
    return false;
  }
  const std::size_t length = be16(p + 4);
  if (length < 8 || length > size) {
    count("bad_udp_header");
    return false;
  }
  out.time_ns = time_ns;
  out.src_ip = src;
  out.dst_ip = dst;
  out.src_port = be16(p);
  out.dst_port = be16(p + 2);
  out.payload.assign(p + 8, p + length);
  return true;
}

void UdpExtractor::expire(std::int64_t time_ns) {
  const auto stale = [time_ns](const Pending& d) {
    const std::int64_t age = time_ns - d.first_ns;
    return age > kFragmentTimeoutNs || age < -kFragmentTimeoutNs;  // a capture clock that jumps back, too
  };
  const auto before = pending_.size();
  pending_.erase(std::remove_if(pending_.begin(), pending_.end(), stale), pending_.end());
  counters_["fragments_dropped"] += static_cast<std::int64_t>(before - pending_.size());
  if (counters_["fragments_dropped"] == 0) counters_.erase("fragments_dropped");
}

bool UdpExtractor::fragment(const std::uint8_t* header, const std::uint8_t* data, std::size_t size, std::size_t offset,
                            bool more, std::int64_t time_ns, UdpDatagram& out) {
  count("fragments");
  expire(time_ns);
  const std::uint32_t src = be32(header + 12), dst = be32(header + 16);
  const std::uint16_t id = be16(header + 4);
  auto it = std::find_if(pending_.begin(), pending_.end(),
                         [&](const Pending& d) { return d.src == src && d.dst == dst && d.id == id; });
  if (offset + size > kMaxIpDatagram) {  // beyond any IP datagram: the whole datagram is lost
    if (it != pending_.end()) pending_.erase(it);
    count("fragments_dropped");
    return false;
  }
  if (it == pending_.end()) {
    if (pending_.size() >= kMaxPendingDatagrams) {
      pending_.pop_front();
      count("fragments_dropped");
    }
    Pending d;
    d.src = src;
    d.dst = dst;
    d.id = id;
    d.first_ns = time_ns;
    pending_.push_back(std::move(d));
    it = pending_.end() - 1;
  }
  Pending& d = *it;
  const std::size_t end = offset + size;
  const bool inconsistent = (!more && d.total > 0 && d.total != end) || (d.total > 0 && end > d.total) ||
                            (!more && std::any_of(d.have.begin(), d.have.end(),
                                                  [end](const auto& r) { return r.second > end; }));
  if (inconsistent || d.have.size() >= kMaxFragmentsPerDatagram) {
    pending_.erase(it);
    count("fragments_dropped");
    return false;
  }
  if (!more) d.total = end;
  if (d.bytes.size() < end) d.bytes.resize(end);
  std::copy(data, data + size, d.bytes.begin() + static_cast<std::ptrdiff_t>(offset));
  d.have.emplace_back(offset, end);
  if (d.total == 0) return false;
  std::vector<std::pair<std::size_t, std::size_t>> ranges = d.have;
  std::sort(ranges.begin(), ranges.end());
  std::size_t covered = 0;
  for (const auto& r : ranges) {
    if (r.first > covered) return false;  // a hole
    covered = std::max(covered, r.second);
  }
  if (covered < d.total) return false;
  const Pending done = std::move(d);
  pending_.erase(it);
  count("reassembled");
  return udp(done.bytes.data(), done.total, done.src, done.dst, time_ns, out);
}

std::size_t UdpExtractor::pendingBytes() const {
  std::size_t n = 0;
  for (const Pending& d : pending_) n += d.bytes.size();
  return n;
}

std::string ipv4ToString(std::uint32_t a) {
  char text[16];
  std::snprintf(text, sizeof text, "%u.%u.%u.%u", (a >> 24) & 0xFF, (a >> 16) & 0xFF, (a >> 8) & 0xFF, a & 0xFF);
  return text;
}

bool parseIpv4(const std::string& text, std::uint32_t& address) {
  unsigned b[4];
  char tail = 0;
  if (std::sscanf(text.c_str(), "%u.%u.%u.%u%c", &b[0], &b[1], &b[2], &b[3], &tail) != 4) return false;
  for (unsigned v : b)
    if (v > 255) return false;
  address = (b[0] << 24) | (b[1] << 16) | (b[2] << 8) | b[3];
  return true;
}

}  // namespace adit::io
