#include "io/rosbag.hpp"

#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace adit::io {
namespace {

constexpr char kVersionLine[] = "#ROSBAG V2.0\n";
constexpr std::size_t kVersionLength = sizeof(kVersionLine) - 1;
enum Op : std::uint8_t { kMessage = 0x02, kBagHeader = 0x03, kIndex = 0x04, kChunk = 0x05, kChunkInfo = 0x06, kConnection = 0x07 };

using Fields = std::map<std::string, std::string>;

std::uint32_t loadU32(const std::uint8_t* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);  // bag files are little-endian, as is every machine adit runs on
  return v;
}

// "name=value" fields packed with uint32 length prefixes; false if a length runs past the end or a field has no '='.
bool parseFields(const std::uint8_t* p, std::size_t size, Fields& fields) {
  std::size_t at = 0;
  while (at < size) {
    if (size - at < 4) return false;
    const std::uint32_t length = loadU32(p + at);
    at += 4;
    if (length > size - at) return false;
    const char* field = reinterpret_cast<const char*>(p + at);
    const char* eq = static_cast<const char*>(std::memchr(field, '=', length));
    if (!eq) return false;
    fields[std::string(field, eq)] = std::string(eq + 1, field + length);
    at += length;
  }
  return true;
}

// A fixed-width little-endian integer field; false if absent or of another width.
template <typename T>
bool field(const Fields& fields, const char* name, T& value) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != sizeof(T)) return false;
  std::memcpy(&value, it->second.data(), sizeof(T));
  return true;
}

bool messageTime(const Fields& fields, std::int64_t& ns) {
  std::uint64_t raw = 0;
  if (!field(fields, "time", raw)) return false;
  ns = static_cast<std::int64_t>(raw & 0xffffffffu) * 1000000000 + static_cast<std::int64_t>(raw >> 32);
  return true;
}

std::string text(const Fields& fields, const char* name) {
  const auto it = fields.find(name);
  return it == fields.end() ? std::string() : it->second;
}

// A connection record: conn and topic in its header, type/md5sum/message_definition in its data.
bool parseConnection(const Fields& header, const std::uint8_t* data, std::size_t size, BagConnection& c) {
  Fields info;
  if (!field(header, "conn", c.id) || !parseFields(data, size, info)) return false;
  c.topic = text(header, "topic");
  c.type = text(info, "type");
  c.md5sum = text(info, "md5sum");
  c.message_definition = text(info, "message_definition");
  return true;
}

// Output grows with what the stream actually produces (never to the declared size up front): a crafted
// size field costs nothing, only real data does.
void grow(std::vector<std::uint8_t>& out, std::size_t used, std::size_t limit) {
  if (used < out.size()) return;
  out.resize(std::min<std::size_t>(limit, std::max<std::size_t>(out.size() * 2, 1u << 16)));
}

bool bz2Decompress(const std::vector<std::uint8_t>& in, std::size_t expected, std::vector<std::uint8_t>& out) {
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) return false;
  s.next_in = const_cast<char*>(reinterpret_cast<const char*>(in.data()));
  s.avail_in = static_cast<unsigned>(in.size());
  std::size_t used = 0;
  int rc = BZ_OK;
  // One byte of headroom beyond `expected` tells an overlong stream from an exact one.
  while (rc == BZ_OK) {
    grow(out, used, expected + 1);
    if (used == out.size()) break;
    s.next_out = reinterpret_cast<char*>(out.data() + used);
    s.avail_out = static_cast<unsigned>(out.size() - used);
    rc = BZ2_bzDecompress(&s);
    used = out.size() - s.avail_out;
    if (rc == BZ_OK && s.avail_in == 0 && s.avail_out > 0) break;  // input ended mid-stream
  }
  BZ2_bzDecompressEnd(&s);
  out.resize(used);
  return rc == BZ_STREAM_END && used == expected;
}

bool lz4Decompress(const std::vector<std::uint8_t>& in, std::size_t expected, std::vector<std::uint8_t>& out) {
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) return false;
  std::size_t in_at = 0, used = 0, hint = 1;
  while (hint != 0 && in_at < in.size()) {
    grow(out, used, expected + 1);
    if (used == out.size()) break;
    std::size_t out_size = out.size() - used, in_size = in.size() - in_at;
    hint = LZ4F_decompress(ctx, out.data() + used, &out_size, in.data() + in_at, &in_size, nullptr);
    if (LZ4F_isError(hint)) break;
    used += out_size;
    in_at += in_size;
    if (in_size == 0 && out_size == 0) break;  // no progress: corrupt
  }
  LZ4F_freeDecompressionContext(ctx);
  out.resize(used);
  return hint == 0 && used == expected;
}

}  // namespace

struct BagReader::Record {
  std::uint8_t op = 0;
  Fields fields;
  std::vector<std::uint8_t> data;
};

BagReader::BagReader(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw ReadError("bag '" + path + "': cannot open: " + std::strerror(errno));
  std::fseek(file_, 0, SEEK_END);
  const long end = std::ftell(file_);
  size_ = end > 0 ? static_cast<std::uint64_t>(end) : 0;
  std::fseek(file_, 0, SEEK_SET);
  char version[kVersionLength] = {};
  if (size_ < kVersionLength || std::fread(version, 1, kVersionLength, file_) != kVersionLength ||
      std::memcmp(version, kVersionLine, kVersionLength) != 0) {
    std::fclose(file_);
    throw ReadError("bag '" + path + "': not a ROS bag format 2.0 file (no '#ROSBAG V2.0' line)");
  }
  pos_ = kVersionLength;
  Record header;
  std::uint64_t index_pos = 0;
  if (!readTopLevel(header) || header.op != kBagHeader || !field(header.fields, "index_pos", index_pos)) {
    std::fclose(file_);
    throw ReadError(stats_.last_error.empty() ? "bag '" + path + "': no bag header record" : stats_.last_error);
  }
  readTrailingConnections(index_pos);
}

BagReader::~BagReader() {
  if (file_) std::fclose(file_);
}

double BagReader::progress() const { return size_ ? static_cast<double>(pos_) / static_cast<double>(size_) : 1.0; }

void BagReader::breakAt(const std::string& why) {
  stats_.truncated = true;
  stats_.last_error = "bag '" + path_ + "': " + why + " at byte " + std::to_string(pos_) + " of " + std::to_string(size_);
  done_ = true;
}

// Reads the record at pos_ (header and data), checking both lengths against the file's remaining bytes.
bool BagReader::readTopLevel(Record& record) {
  if (pos_ >= size_) return false;
  std::uint8_t length[4];
  const std::uint64_t left = size_ - pos_;
  if (std::fseek(file_, static_cast<long>(pos_), SEEK_SET) != 0 || left < 8 || std::fread(length, 1, 4, file_) != 4) {
    breakAt("truncated record");
    return false;
  }
  const std::uint32_t header_length = loadU32(length);
  if (header_length > left - 8) {
    breakAt("record header length " + std::to_string(header_length) + " runs past the end");
    return false;
  }
  std::vector<std::uint8_t> header(header_length);
  record.fields.clear();
  if (std::fread(header.data(), 1, header.size(), file_) != header.size() || std::fread(length, 1, 4, file_) != 4 ||
      !parseFields(header.data(), header.size(), record.fields) || !field(record.fields, "op", record.op)) {
    breakAt("malformed record header");
    return false;
  }
  const std::uint32_t data_length = loadU32(length);
  if (data_length > left - 8 - header_length) {
    breakAt("record data length " + std::to_string(data_length) + " runs past the end");
    return false;
  }
  record.data.resize(data_length);
  if (std::fread(record.data.data(), 1, data_length, file_) != data_length) {
    breakAt("read error");
    return false;
  }
  pos_ += 8 + header_length + data_length;
  return true;
}

void BagReader::readTrailingConnections(std::uint64_t index_pos) {
  if (index_pos <= pos_ || index_pos >= size_) return;  // unindexed (interrupted recording) or bogus
  const std::uint64_t resume = pos_;
  const BagReadStats before = stats_;
  pos_ = index_pos;
  Record r;
  while (readTopLevel(r)) {
    BagConnection c;
    std::uint64_t chunk_pos = 0;
    if (r.op == kConnection && parseConnection(r.fields, r.data.data(), r.data.size(), c)) connections_[c.id] = c;
    if (r.op == kChunkInfo && field(r.fields, "chunk_pos", chunk_pos) && chunk_pos < index_pos) chunk_positions_.push_back(chunk_pos);
  }
  std::sort(chunk_positions_.begin(), chunk_positions_.end());
  stats_ = before;  // a damaged index is not the data's problem: the chunks are still read
  done_ = false;
  pos_ = resume;
}

void BagReader::loadChunk(const Record& chunk) {
  ++stats_.chunks;
  const std::string compression = text(chunk.fields, "compression");
  std::uint32_t size = 0;
  std::vector<std::uint8_t> plain;
  const auto lose = [&](const std::string& why) {
    ++stats_.chunks_lost;
    stats_.last_error = "bag '" + path_ + "': chunk " + std::to_string(stats_.chunks) + " ending at byte " +
                        std::to_string(pos_) + " lost: " + why;
  };
  if (!field(chunk.fields, "size", size)) return lose("no size field");
  if (size > kMaxBagChunkBytes) return lose("declared size " + std::to_string(size) + " too large");
  bool ok = false;
  if (compression == "none") {
    ok = chunk.data.size() == size;
    plain = chunk.data;
  } else if (compression == "bz2") {
    ok = bz2Decompress(chunk.data, size, plain);
  } else if (compression == "lz4") {
    ok = lz4Decompress(chunk.data, size, plain);
  } else {
    return lose("unknown compression '" + compression + "'");
  }
  if (!ok) return lose(compression + " data does not decompress to the declared " + std::to_string(size) + " bytes");

  std::deque<BagMessage> messages;
  std::size_t at = 0;
  while (at < plain.size()) {
    const std::size_t left = plain.size() - at;
    if (left < 8) return lose("truncated record inside");
    const std::uint32_t header_length = loadU32(plain.data() + at);
    if (header_length > left - 8) return lose("record header runs past the chunk");
    Fields fields;
    std::uint8_t op = 0;
    if (!parseFields(plain.data() + at + 4, header_length, fields) || !field(fields, "op", op))
      return lose("malformed record header inside");
    const std::uint32_t data_length = loadU32(plain.data() + at + 4 + header_length);
    if (data_length > left - 8 - header_length) return lose("record data runs past the chunk");
    const std::uint8_t* data = plain.data() + at + 8 + header_length;
    at += 8 + header_length + data_length;
    if (op == kConnection) {
      BagConnection c;
      if (!parseConnection(fields, data, data_length, c)) return lose("malformed connection record");
      connections_[c.id] = c;
    } else if (op == kMessage) {
      BagMessage m;
      if (!field(fields, "conn", m.conn) || !messageTime(fields, m.time_ns)) return lose("malformed message record");
      m.data.assign(data, data + data_length);
      messages.push_back(std::move(m));
    }
  }
  for (BagMessage& m : messages) pending_.push_back(std::move(m));
}

// After a framing break at pos_: jump to the first indexed chunk beyond it, counting the chunks passed over.
bool BagReader::resynchronise() {
  const auto next = std::upper_bound(chunk_positions_.begin(), chunk_positions_.end(), pos_);
  if (next == chunk_positions_.end()) return false;
  const auto skipped = std::count_if(chunk_positions_.begin(), next, [&](std::uint64_t p) { return p >= pos_; });
  const std::uint64_t from = pos_;
  stats_.chunks_lost += skipped;
  stats_.chunks += skipped;
  ++stats_.resyncs;
  stats_.last_error += "; resumed at the next indexed chunk, byte " + std::to_string(*next) + " (" +
                       std::to_string(*next - from) + " bytes, " + std::to_string(skipped) + " chunk(s) lost)";
  pos_ = *next;
  stats_.truncated = false;
  done_ = false;
  return true;
}

bool BagReader::next(BagMessage& message) {
  for (;;) {
    while (!pending_.empty()) {
      message = std::move(pending_.front());
      pending_.pop_front();
      if (!connections_.count(message.conn)) {
        ++stats_.unknown_conn;
        continue;
      }
      ++stats_.messages;
      return true;
    }
    Record r;
    if (done_) return false;
    if (!readTopLevel(r)) {
      if (stats_.truncated && resynchronise()) continue;
      return false;
    }
    if (r.op == kChunk) {
      loadChunk(r);
    } else if (r.op == kConnection) {
      BagConnection c;
      if (parseConnection(r.fields, r.data.data(), r.data.size(), c)) connections_[c.id] = c;
    } else if (r.op == kMessage) {  // not written by rosbag 2.0, but legal
      BagMessage m;
      if (field(r.fields, "conn", m.conn) && messageTime(r.fields, m.time_ns)) {
        m.data = std::move(r.data);
        pending_.push_back(std::move(m));
      }
    }
  }
}

}  // namespace adit::io
