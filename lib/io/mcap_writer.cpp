#include "io/mcap_writer.hpp"

#include <zstd.h>

#include <algorithm>
#include <stdexcept>
#include <type_traits>

namespace adit::io {
namespace {

constexpr char kMagic[8] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// The fields of one record, little-endian, with MCAP's length prefixes: uint32 for strings, maps and arrays.
class Fields {
 public:
  template <class T>
  Fields& num(T value) {
    static_assert(std::is_integral_v<T>, "MCAP fields are integers");
    for (std::size_t i = 0; i < sizeof(T); ++i)
      bytes_.push_back(static_cast<char>((static_cast<std::uint64_t>(value) >> (8 * i)) & 0xFFu));
    return *this;
  }
  // A string, a map or an array: uint32 byte length, then the bytes.
  Fields& prefixed(const std::string& bytes) {
    if (bytes.size() > 0xFFFFFFFFu) throw std::runtime_error("MCAP: a field longer than 4 GB");
    num(static_cast<std::uint32_t>(bytes.size()));
    bytes_ += bytes;
    return *this;
  }
  Fields& raw(const std::string& bytes) {
    bytes_ += bytes;
    return *this;
  }
  const std::string& bytes() const { return bytes_; }
  // The record: opcode, uint64 content length, content.
  std::string record(Op op) const {
    Fields r;
    r.num(static_cast<std::uint8_t>(op)).num(static_cast<std::uint64_t>(bytes_.size()));
    return r.bytes_ + bytes_;
  }

 private:
  std::string bytes_;
};

template <class V>
std::string u16Map(const std::map<std::uint16_t, V>& map) {
  Fields f;
  for (const auto& [key, value] : map) f.num(key).num(static_cast<std::uint64_t>(value));
  return f.bytes();
}

std::string zstdCompress(const std::string& bytes, int level) {
  std::string out(ZSTD_compressBound(bytes.size()), '\0');
  const std::size_t n = ZSTD_compress(out.data(), out.size(), bytes.data(), bytes.size(), level);
  if (ZSTD_isError(n)) throw std::runtime_error(std::string("MCAP: zstd: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

}  // namespace

McapWriter::McapWriter(std::ostream& out, McapOptions options) : out_(out), options_(std::move(options)) {
  emit(std::string(kMagic, sizeof(kMagic)));
  emit(Fields().prefixed(options_.profile).prefixed(options_.library).record(kHeader));
}

void McapWriter::emit(const std::string& bytes) {
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out_) throw std::runtime_error("MCAP: write failed");
  if (in_data_section_) data_crc_.update(bytes.data(), bytes.size());
  offset_ += bytes.size();
}

std::uint16_t McapWriter::addSchema(const std::string& name, const std::string& encoding, const std::string& data) {
  if (schema_records_.size() >= 0xFFFEu) throw std::runtime_error("MCAP: too many schemas");
  const auto id = static_cast<std::uint16_t>(schema_records_.size() + 1);
  schema_records_.push_back(Fields().num(id).prefixed(name).prefixed(encoding).prefixed(data).record(kSchema));
  chunk_.records += schema_records_.back();
  return id;
}

std::uint16_t McapWriter::addChannel(std::uint16_t schema_id, const std::string& topic,
                                     const std::string& message_encoding,
                                     const std::map<std::string, std::string>& metadata) {
  if (schema_id > schema_records_.size()) throw std::runtime_error("MCAP: channel '" + topic + "' names an unknown schema");
  if (channel_records_.size() >= 0xFFFEu) throw std::runtime_error("MCAP: too many channels");
  const auto id = static_cast<std::uint16_t>(channel_records_.size() + 1);
  Fields meta;
  for (const auto& [key, value] : metadata) meta.prefixed(key).prefixed(value);
  channel_records_.push_back(
      Fields().num(id).num(schema_id).prefixed(topic).prefixed(message_encoding).prefixed(meta.bytes()).record(kChannel));
  chunk_.records += channel_records_.back();
  stats_.per_channel[id] = 0;
  return id;
}

void McapWriter::write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
                       const std::string& data) {
  if (finished_) throw std::runtime_error("MCAP: write after finish");
  if (channel_id == 0 || channel_id > channel_records_.size()) throw std::runtime_error("MCAP: unknown channel");
  const std::uint32_t sequence = next_sequence_[channel_id]++;
  chunk_.index[channel_id].emplace_back(log_time_ns, chunk_.records.size());
  chunk_.records += Fields().num(channel_id).num(sequence).num(log_time_ns).num(publish_time_ns).raw(data).record(kMessage);
  chunk_.start_ns = chunk_.has_messages ? std::min(chunk_.start_ns, log_time_ns) : log_time_ns;
  chunk_.end_ns = chunk_.has_messages ? std::max(chunk_.end_ns, log_time_ns) : log_time_ns;
  chunk_.has_messages = true;
  stats_.start_ns = stats_.messages ? std::min(stats_.start_ns, log_time_ns) : log_time_ns;
  stats_.end_ns = stats_.messages ? std::max(stats_.end_ns, log_time_ns) : log_time_ns;
  ++stats_.messages;
  ++stats_.per_channel[channel_id];
  if (chunk_.records.size() >= options_.chunk_bytes) flushChunk();
}

std::string McapWriter::chunkRecord(const std::string& stored) const {
  Fields f;
  f.num(chunk_.start_ns).num(chunk_.end_ns).num(static_cast<std::uint64_t>(chunk_.records.size()));
  f.num(crc32(chunk_.records.data(), chunk_.records.size()));
  f.prefixed(options_.compression == McapCompression::Zstd ? "zstd" : "");
  f.num(static_cast<std::uint64_t>(stored.size())).raw(stored);
  return f.record(kChunk);
}

void McapWriter::flushChunk() {
  if (chunk_.records.empty()) return;
  const bool zstd = options_.compression == McapCompression::Zstd;
  const std::string stored = zstd ? zstdCompress(chunk_.records, options_.zstd_level) : chunk_.records;
  ChunkIndex index;
  index.start_ns = chunk_.start_ns;
  index.end_ns = chunk_.end_ns;
  index.offset = offset_;
  index.compressed = stored.size();
  index.uncompressed = chunk_.records.size();
  const std::string record = chunkRecord(stored);
  index.length = record.size();
  emit(record);
  const std::uint64_t indexes_start = offset_;
  for (auto& [channel, entries] : chunk_.index) {
    // Readers binary-search an index by time: order it by log time (stable: equal times keep their order).
    std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    Fields array;
    for (const auto& [time, position] : entries) array.num(time).num(position);
    index.message_index_offsets[channel] = offset_;
    emit(Fields().num(channel).prefixed(array.bytes()).record(kMessageIndex));
  }
  index.message_index_length = offset_ - indexes_start;
  chunk_indexes_.push_back(std::move(index));
  ++stats_.chunks;
  chunk_ = OpenChunk{};
}

void McapWriter::finish() {
  if (finished_) throw std::runtime_error("MCAP: finish called twice");
  flushChunk();
  in_data_section_ = false;
  emit(Fields().num(data_crc_.value()).record(kDataEnd));
  writeSummary();
  out_.flush();
  if (!out_) throw std::runtime_error("MCAP: write failed");
  finished_ = true;
}

void McapWriter::writeSummary() {
  const std::uint64_t summary_start = offset_;
  std::string tail;
  struct Group {
    Op op;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  const auto group = [&](Op op, const std::vector<std::string>& records) {
    if (records.empty()) return;
    const std::uint64_t start = summary_start + tail.size();
    for (const auto& r : records) tail += r;
    groups.push_back({op, start, summary_start + tail.size() - start});
  };
  group(kSchema, schema_records_);
  group(kChannel, channel_records_);
  std::vector<std::string> chunk_index_records;
  for (const ChunkIndex& c : chunk_indexes_) {
    Fields f;
    f.num(c.start_ns).num(c.end_ns).num(c.offset).num(c.length).prefixed(u16Map(c.message_index_offsets));
    f.num(c.message_index_length).prefixed(options_.compression == McapCompression::Zstd ? "zstd" : "");
    f.num(c.compressed).num(c.uncompressed);
    chunk_index_records.push_back(f.record(kChunkIndex));
  }
  group(kChunkIndex, chunk_index_records);
  Fields statistics;
  statistics.num(stats_.messages).num(static_cast<std::uint16_t>(schema_records_.size()));
  statistics.num(static_cast<std::uint32_t>(channel_records_.size())).num(std::uint32_t{0}).num(std::uint32_t{0});
  statistics.num(stats_.chunks).num(stats_.start_ns).num(stats_.end_ns).prefixed(u16Map(stats_.per_channel));
  group(kStatistics, {statistics.record(kStatistics)});

  const std::uint64_t summary_offset_start = summary_start + tail.size();
  for (const Group& g : groups)
    tail += Fields().num(static_cast<std::uint8_t>(g.op)).num(g.start).num(g.length).record(kSummaryOffset);
  // The footer's CRC covers the summary, the summary offsets and the footer up to the CRC itself.
  Fields footer;
  footer.num(summary_start).num(summary_offset_start).num(std::uint32_t{0});
  std::string footer_record = footer.record(kFooter);
  footer_record.resize(footer_record.size() - 4);
  tail += footer_record;
  tail += Fields().num(crc32(tail.data(), tail.size())).bytes();
  tail += std::string(kMagic, sizeof(kMagic));
  emit(tail);
}

}  // namespace adit::io
