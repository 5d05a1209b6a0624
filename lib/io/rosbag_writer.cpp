#include "io/rosbag_writer.hpp"

#include <bzlib.h>
#include <lz4frame.h>

#include <stdexcept>

namespace adit::io {
namespace {

enum Op : char { kMessage = 0x02, kBagHeader = 0x03, kIndexData = 0x04, kChunk = 0x05, kChunkInfo = 0x06, kConnection = 0x07 };

// ROS serialisation is little-endian; so is every machine adit builds for (core/byte_codec.hpp checks it).
template <typename T>
std::string le(T v) {
  return std::string(reinterpret_cast<const char*>(&v), sizeof(T));
}
std::string u32(std::uint64_t v) { return le(static_cast<std::uint32_t>(v)); }
std::string rosTime(std::int64_t ns) { return u32(ns / 1000000000) + u32(ns % 1000000000); }
std::string field(const std::string& name, const std::string& value) { return u32(name.size() + 1 + value.size()) + name + "=" + value; }
std::string opField(char op) { return field("op", std::string(1, op)); }
std::string record(const std::string& header, const std::string& data) { return u32(header.size()) + header + u32(data.size()) + data; }

std::string compress(const std::string& how, const std::string& plain) {
  if (how == "none") return plain;
  if (how == "bz2") {
    // bzip2's documented bound for the output: 1 % more than the input plus 600 bytes.
    auto size = static_cast<unsigned int>(plain.size() + plain.size() / 100 + 601);
    std::string out(size, '\0');
    if (BZ2_bzBuffToBuffCompress(out.data(), &size, const_cast<char*>(plain.data()), static_cast<unsigned int>(plain.size()),
                                 9, 0, 30) != BZ_OK)
      throw std::runtime_error("bz2 compression of a bag chunk failed");
    out.resize(size);
    return out;
  }
  // lz4: the frame options roslz4 uses: independent 1 MB blocks, a content checksum, no content size.
  LZ4F_preferences_t prefs{};
  prefs.frameInfo.blockSizeID = LZ4F_max1MB;
  prefs.frameInfo.blockMode = LZ4F_blockIndependent;
  prefs.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
  std::string out(LZ4F_compressFrameBound(plain.size(), &prefs), '\0');
  const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), plain.data(), plain.size(), &prefs);
  if (LZ4F_isError(n)) throw std::runtime_error(std::string("lz4 compression of a bag chunk failed: ") + LZ4F_getErrorName(n));
  out.resize(n);
  return out;
}

}  // namespace

RosbagWriter::RosbagWriter(std::ostream& out, Options options) : out_(out), options_(std::move(options)) {
  if (options_.compression != "none" && options_.compression != "bz2" && options_.compression != "lz4")
    throw std::invalid_argument("bag compression must be none, bz2 or lz4, not '" + options_.compression + "'");
  const auto at = out_.tellp();
  start_ = at < 0 ? 0 : static_cast<std::uint64_t>(at);
  put("#ROSBAG V2.0\n");
  put(bagHeaderRecord(0));
}

void RosbagWriter::put(const std::string& bytes) {
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out_) throw std::runtime_error("writing the bag failed");
  written_ += bytes.size();
}

// Header and data together fill options_.header_padding bytes, so the record's size does not depend on
// index_pos and the final rewrite lands exactly over the placeholder.
std::string RosbagWriter::bagHeaderRecord(std::uint64_t index_pos) const {
  const std::string h = field("chunk_count", u32(chunks_.size())) + field("conn_count", u32(connections_.size())) +
                        field("index_pos", le<std::uint64_t>(index_pos)) + opField(kBagHeader);
  const std::size_t used = h.size() + 8;
  return record(h, std::string(options_.header_padding > used ? options_.header_padding - used : 0, ' '));
}

void RosbagWriter::addConnection(std::uint32_t id, const std::string& topic, const RosMessageType& type) {
  for (const Connection& c : connections_)
    if (c.id == id) throw std::invalid_argument("bag connection " + std::to_string(id) + " added twice");
  connections_.push_back({id, topic, type});
  connection_in_chunk_.push_back(false);
}

const RosbagWriter::Connection& RosbagWriter::connection(std::uint32_t id) const {
  for (const Connection& c : connections_)
    if (c.id == id) return c;
  throw std::out_of_range("bag connection " + std::to_string(id) + " was not added");
}

std::string RosbagWriter::connectionRecord(const Connection& c) const {
  const std::string h = opField(kConnection) + field("conn", u32(c.id)) + field("topic", c.topic);
  const std::string d = field("topic", c.topic) + field("type", c.type.name) + field("md5sum", c.type.md5sum) +
                        field("message_definition", c.type.definition);
  return record(h, d);
}

void RosbagWriter::write(std::uint32_t conn, std::int64_t time_ns, const std::uint8_t* data, std::size_t size) {
  if (finished_) throw std::logic_error("bag written after finish()");
  if (time_ns < 0) throw std::invalid_argument("a bag cannot hold a time before 1970");
  const Connection& c = connection(conn);
  const std::size_t index = static_cast<std::size_t>(&c - connections_.data());
  if (!connection_in_chunk_[index]) {  // rosbag repeats each connection's record in every chunk that uses it
    chunk_ += connectionRecord(c);
    connection_in_chunk_[index] = true;
  }
  if (chunk_index_.empty() || time_ns < chunk_start_ns_) chunk_start_ns_ = time_ns;
  if (chunk_index_.empty() || time_ns > chunk_end_ns_) chunk_end_ns_ = time_ns;
  chunk_index_[conn].push_back({time_ns, static_cast<std::uint32_t>(chunk_.size())});
  const std::string h = opField(kMessage) + field("conn", u32(conn)) + field("time", rosTime(time_ns));
  chunk_ += record(h, std::string(reinterpret_cast<const char*>(data), size));
  ++messages_;
  if (chunk_.size() >= options_.chunk_bytes) endChunk();
}

std::pair<std::uint64_t, std::uint64_t> RosbagWriter::endChunk() {
  if (chunk_index_.empty()) return {0, 0};
  const std::string stored = compress(options_.compression, chunk_);
  const std::string h = field("compression", options_.compression) + opField(kChunk) + field("size", u32(chunk_.size()));
  ChunkInfo info{start_ + written_, chunk_start_ns_, chunk_end_ns_, {}};
  const std::uint64_t begin = info.pos + 4 + h.size() + 4;
  put(record(h, stored));
  for (const auto& [conn, entries] : chunk_index_) {  // std::map: connections in id order, as rosbag writes them
    std::string d;
    for (const IndexEntry& e : entries) d += rosTime(e.time_ns) + u32(e.offset);
    put(record(field("ver", u32(1)) + field("conn", u32(conn)) + field("count", u32(entries.size())) + opField(kIndexData), d));
    info.counts[conn] = static_cast<std::uint32_t>(entries.size());
  }
  chunk_pos_.push_back(info.pos);
  chunks_.push_back(std::move(info));
  chunk_.clear();
  chunk_index_.clear();
  connection_in_chunk_.assign(connections_.size(), false);
  return {begin, begin + stored.size()};
}

void RosbagWriter::finish() {
  if (finished_) return;
  endChunk();
  const std::uint64_t index_pos = start_ + written_;
  for (const Connection& c : connections_) put(connectionRecord(c));
  for (const ChunkInfo& info : chunks_) {
    std::string d;
    for (const auto& [conn, count] : info.counts) d += u32(conn) + u32(count);
    put(record(opField(kChunkInfo) + field("ver", u32(1)) + field("chunk_pos", le<std::uint64_t>(info.pos)) +
                   field("start_time", rosTime(info.start_ns)) + field("end_time", rosTime(info.end_ns)) +
                   field("count", u32(info.counts.size())),
               d));
  }
  finished_ = true;
  const auto end = out_.tellp();
  out_.seekp(static_cast<std::streamoff>(start_ + 13));  // past "#ROSBAG V2.0\n"
  const std::string header = bagHeaderRecord(index_pos);
  out_.write(header.data(), static_cast<std::streamsize>(header.size()));
  out_.seekp(end);
  out_.flush();
  if (!out_) throw std::runtime_error("writing the bag's header failed (is the stream seekable?)");
}

}  // namespace adit::io
