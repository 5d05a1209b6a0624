#include "io/capture_file.hpp"

#include "io/io_error.hpp"

#include <algorithm>
#include <array>
#include <limits>

namespace adit::io {
namespace {

constexpr std::uint32_t kClassicMicros = 0xA1B2C3D4, kClassicNanos = 0xA1B23C4D;
constexpr std::uint32_t kSectionHeader = 0x0A0D0D0A, kByteOrderMagic = 0x1A2B3C4D;
constexpr std::uint32_t kInterfaceBlock = 1, kObsoletePacketBlock = 2, kSimplePacketBlock = 3,
                        kEnhancedPacketBlock = 6;
// Non-packet blocks (name resolution, statistics, comments) are skipped by their length; more than this is
// not a block but damage.
constexpr std::uint32_t kMaxBlockBytes = 16 * 1024 * 1024;

std::uint32_t byteSwap32(std::uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xFF00u) | ((v << 8) & 0xFF0000u) | (v << 24);
}
std::uint32_t readLe32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
std::int64_t saturatedAdd(std::int64_t a, std::int64_t b) {
  if (b > 0 && a > std::numeric_limits<std::int64_t>::max() - b) return std::numeric_limits<std::int64_t>::max();
  if (b < 0 && a < std::numeric_limits<std::int64_t>::min() - b) return std::numeric_limits<std::int64_t>::min();
  return a + b;
}

}  // namespace

std::int64_t captureTimeNs(std::uint64_t stamp, int exponent, bool binary) {
  constexpr std::uint64_t kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  if (binary) {
    // Keep at most 30 fraction bits so that fraction * 1e9 fits 64 bits (2^-30 s < 1 ns).
    const int drop = exponent > 30 ? exponent - 30 : 0;
    const std::uint64_t units = drop >= 64 ? 0 : stamp >> drop;
    const int bits = exponent - drop;
    const std::uint64_t seconds = units >> bits, fraction = units & ((std::uint64_t{1} << bits) - 1);
    if (seconds > kMax / 1000000000ULL - 1) return static_cast<std::int64_t>(kMax);
    return static_cast<std::int64_t>(seconds * 1000000000ULL + ((fraction * 1000000000ULL) >> bits));
  }
  std::uint64_t scale = 1;
  for (int i = exponent; i < 9; ++i) scale *= 10;
  for (int i = 9; i < exponent; ++i) stamp /= 10;
  if (stamp > kMax / scale) return static_cast<std::int64_t>(kMax);
  return static_cast<std::int64_t>(stamp * scale);
}

CaptureReader::CaptureReader(std::istream& in, std::string name) : in_(in), name_(std::move(name)) {
  std::array<std::uint8_t, 4> head{};
  if (!readExact(head.data(), head.size()))
    throw ReadError("capture '" + name_ + "': too short to be a pcap or pcapng file");
  const std::uint32_t magic = readLe32(head.data());
  if (magic == kSectionHeader) {
    pcapng_ = true;
    // The section header is read as the first block by nextPcapng(); its type is palindromic.
    std::array<std::uint8_t, 8> rest{};
    if (!readExact(rest.data(), rest.size())) throw ReadError("capture '" + name_ + "': pcapng section header cut short");
    const std::uint32_t order = readLe32(rest.data() + 4);
    if (order != kByteOrderMagic && byteSwap32(order) != kByteOrderMagic)
      throw ReadError("capture '" + name_ + "': pcapng section header without its byte-order magic");
    swapped_ = order != kByteOrderMagic;
    const std::uint32_t length = u32(rest.data());
    if (length < 28 || length % 4 != 0 || length > kMaxBlockBytes)
      throw ReadError("capture '" + name_ + "': pcapng section header length " + std::to_string(length));
    std::vector<std::uint8_t> body(length - 8);
    std::copy(rest.begin() + 4, rest.end(), body.begin());
    if (!readExact(body.data() + 4, body.size() - 4)) throw ReadError("capture '" + name_ + "': pcapng section header cut short");
    readSectionHeader(body);
    return;
  }
  if (magic == kClassicMicros || magic == kClassicNanos) swapped_ = false;
  else if (byteSwap32(magic) == kClassicMicros || byteSwap32(magic) == kClassicNanos) swapped_ = true;
  else throw ReadError("capture '" + name_ + "': not a pcap or pcapng file (unknown magic number)");
  classic_nanos_ = (swapped_ ? byteSwap32(magic) : magic) == kClassicNanos;
  std::array<std::uint8_t, 20> header{};
  if (!readExact(header.data(), header.size())) throw ReadError("capture '" + name_ + "': pcap file header cut short");
  // Bits 28-31 of the link-type field carry the FCS length (if any), not the type.
  classic_link_ = u32(header.data() + 16) & 0x0FFFFFFFu;
}

bool CaptureReader::readExact(std::uint8_t* out, std::size_t n) {
  in_.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n));
  return static_cast<std::size_t>(in_.gcount()) == n;
}

bool CaptureReader::readAppending(std::vector<std::uint8_t>& out, std::size_t n) {
  // In steps, so that a length the file does not back costs no more memory than the bytes it holds.
  constexpr std::size_t kStep = 64 * 1024;
  while (n > 0) {
    const std::size_t step = std::min(n, kStep), at = out.size();
    out.resize(at + step);
    if (!readExact(out.data() + at, step)) return false;
    n -= step;
  }
  return true;
}

std::uint16_t CaptureReader::u16(const std::uint8_t* p) const {
  return swapped_ ? static_cast<std::uint16_t>((p[0] << 8) | p[1]) : static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
std::uint32_t CaptureReader::u32(const std::uint8_t* p) const {
  const std::uint32_t v = readLe32(p);
  return swapped_ ? byteSwap32(v) : v;
}

void CaptureReader::damage(const std::string& counter, const std::string& what) {
  counters_[counter] += 1;
  last_error_ = "capture '" + name_ + "': " + what;
}

bool CaptureReader::next(CapturedFrame& frame) {
  if (ended_) return false;
  const bool got = pcapng_ ? nextPcapng(frame) : nextClassic(frame);
  if (!got) ended_ = true;
  else ++records_;
  return got;
}

bool CaptureReader::nextClassic(CapturedFrame& frame) {
  std::array<std::uint8_t, 16> header{};
  in_.read(reinterpret_cast<char*>(header.data()), header.size());
  const auto got = static_cast<std::size_t>(in_.gcount());
  if (got == 0) return false;  // the clean end
  const std::string where = "record " + std::to_string(records_ + 1);
  if (got < header.size()) {
    damage("truncated_record", where + ": header cut short by the end of the file");
    return false;
  }
  const std::uint32_t captured = u32(header.data() + 8), original = u32(header.data() + 12);
  if (captured > kMaxCaptureRecordBytes) {
    damage("corrupt_record", where + ": captured length " + std::to_string(captured) + " bytes is not plausible");
    return false;
  }
  frame.bytes.clear();
  if (!readAppending(frame.bytes, captured)) {
    damage("truncated_record", where + ": " + std::to_string(captured) + " bytes announced, the file ends first");
    return false;
  }
  frame.link_type = classic_link_;
  frame.original_length = original < captured ? captured : original;
  const std::uint64_t seconds = u32(header.data()), fraction = u32(header.data() + 4);
  frame.time_ns = saturatedAdd(captureTimeNs(seconds, 0, false),
                               static_cast<std::int64_t>(classic_nanos_ ? fraction : fraction * 1000));
  return true;
}

bool CaptureReader::nextPcapng(CapturedFrame& frame) {
  for (;;) {
    std::array<std::uint8_t, 8> head{};
    in_.read(reinterpret_cast<char*>(head.data()), head.size());
    const auto got = static_cast<std::size_t>(in_.gcount());
    if (got == 0) return false;
    const std::string where = "block after record " + std::to_string(records_);
    if (got < head.size()) {
      damage("truncated_record", where + ": cut short by the end of the file");
      return false;
    }
    const std::uint32_t raw_type = readLe32(head.data());
    std::vector<std::uint8_t> body;
    if (raw_type == kSectionHeader) {  // a new section may change the byte order
      std::array<std::uint8_t, 4> order{};
      if (!readExact(order.data(), 4)) {
        damage("truncated_record", where + ": section header cut short");
        return false;
      }
      const std::uint32_t magic = readLe32(order.data());
      if (magic != kByteOrderMagic && byteSwap32(magic) != kByteOrderMagic) {
        damage("corrupt_record", where + ": section header without its byte-order magic");
        return false;
      }
      swapped_ = magic != kByteOrderMagic;
      body.assign(order.begin(), order.end());
    }
    const std::uint32_t type = u32(head.data()), length = u32(head.data() + 4);
    const std::uint32_t limit = type == kEnhancedPacketBlock || type == kSimplePacketBlock ||
                                        type == kObsoletePacketBlock ? kMaxCaptureRecordBytes + 64 : kMaxBlockBytes;
    if (length < 12 + body.size() || length % 4 != 0 || length > limit) {
      damage("corrupt_record", where + ": block length " + std::to_string(length) + " is not valid");
      return false;
    }
    if (!readAppending(body, length - 8 - body.size())) {  // the body and the trailing length copy
      damage("truncated_record", where + ": " + std::to_string(length) + " bytes announced, the file ends first");
      return false;
    }
    if (u32(body.data() + body.size() - 4) != length) {
      damage("corrupt_record", where + ": the block's two lengths disagree");
      return false;
    }
    body.resize(body.size() - 4);
    if (type == kSectionHeader) {
      if (!readSectionHeader(body)) return false;
    } else if (type == kInterfaceBlock) {
      readInterface(body);
    } else if (type == kEnhancedPacketBlock || type == kSimplePacketBlock || type == kObsoletePacketBlock) {
      if (packetFromBlock(type, body, frame)) return true;
    } else {
      counters_["skipped_block"] += 1;
    }
  }
}

bool CaptureReader::readSectionHeader(const std::vector<std::uint8_t>& body) {
  if (body.size() < 16) {
    damage("corrupt_record", "pcapng section header too short");
    return false;
  }
  if (u16(body.data() + 4) != 1) {
    damage("corrupt_record", "pcapng major version " + std::to_string(u16(body.data() + 4)) + " (1 is known)");
    return false;
  }
  interfaces_.clear();  // interface ids are per section
  return true;
}

void CaptureReader::readInterface(const std::vector<std::uint8_t>& body) {
  Interface itf;
  if (body.size() < 8) {
    damage("corrupt_record", "pcapng interface block too short");
    interfaces_.push_back(itf);  // keep the ids of later interfaces right; its packets are skipped
    return;
  }
  itf.link_type = u16(body.data());
  itf.snap_length = u32(body.data() + 4);
  // Options: code u16, length u16, value padded to 4 bytes; code 0 ends them.
  for (std::size_t at = 8; at + 4 <= body.size();) {
    const std::uint16_t code = u16(body.data() + at), size = u16(body.data() + at + 2);
    const std::size_t value = at + 4;
    if (code == 0 || value + size > body.size()) break;
    if (code == 9 && size >= 1) {  // if_tsresol
      const std::uint8_t r = body[value];
      itf.binary_resolution = (r & 0x80) != 0;
      itf.exponent = r & 0x7F;
      if ((!itf.binary_resolution && itf.exponent > 18) || (itf.binary_resolution && itf.exponent > 63)) {
        damage("bad_timestamp_resolution", "pcapng interface timestamp resolution " + std::to_string(r) +
                                               " is not usable; microseconds assumed");
        itf.binary_resolution = false;
        itf.exponent = 6;
      }
    } else if (code == 14 && size >= 8) {  // if_tsoffset, seconds
      const std::uint64_t lo = swapped_ ? u32(body.data() + value + 4) : u32(body.data() + value);
      const std::uint64_t hi = swapped_ ? u32(body.data() + value) : u32(body.data() + value + 4);
      const std::int64_t offset = static_cast<std::int64_t>(lo | (hi << 32));
      // Beyond +-300 years the offset is damage, not a time zone or a clock correction.
      itf.offset_s = (offset > -10000000000LL && offset < 10000000000LL) ? offset : 0;
    }
    at = value + ((size + 3u) & ~3u);
  }
  interfaces_.push_back(itf);
}

bool CaptureReader::packetFromBlock(std::uint32_t type, const std::vector<std::uint8_t>& body, CapturedFrame& frame) {
  std::size_t data_at = 0;
  std::uint32_t interface = 0, captured = 0, original = 0;
  std::uint64_t stamp = 0;
  bool stamped = true;
  if (type == kSimplePacketBlock) {
    if (body.size() < 4) {
      damage("corrupt_record", "pcapng simple packet block too short");
      return false;
    }
    original = u32(body.data());
    data_at = 4;
    captured = static_cast<std::uint32_t>(std::min<std::size_t>(original, body.size() - 4));
    if (!interfaces_.empty() && interfaces_[0].snap_length > 0 && captured > interfaces_[0].snap_length)
      captured = interfaces_[0].snap_length;
    stamped = false;
  } else {
    if (body.size() < 20) {
      damage("corrupt_record", "pcapng packet block too short");
      return false;
    }
    interface = type == kObsoletePacketBlock ? u16(body.data()) : u32(body.data());
    stamp = (static_cast<std::uint64_t>(u32(body.data() + 4)) << 32) | u32(body.data() + 8);
    captured = u32(body.data() + 12);
    original = u32(body.data() + 16);
    data_at = 20;
    if (captured > body.size() - 20) {
      damage("corrupt_record", "pcapng packet block: captured length " + std::to_string(captured) +
                                   " exceeds its block");
      return false;
    }
  }
  if (interface >= interfaces_.size()) {
    damage("unknown_interface", "packet of interface " + std::to_string(interface) + ", which no block described");
    return false;
  }
  const Interface& itf = interfaces_[interface];
  frame.link_type = itf.link_type;
  frame.original_length = original < captured ? captured : original;
  frame.bytes.assign(body.begin() + static_cast<std::ptrdiff_t>(data_at),
                     body.begin() + static_cast<std::ptrdiff_t>(data_at + captured));
  frame.time_ns = stamped ? saturatedAdd(captureTimeNs(stamp, itf.exponent, itf.binary_resolution),
                                         itf.offset_s * 1000000000LL)
                          : last_time_ns_;
  last_time_ns_ = frame.time_ns;
  return true;
}

}  // namespace adit::io
