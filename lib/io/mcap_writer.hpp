// An MCAP writer (the container of Foxglove, Lichtblick and ROS 2 bags; the format's specification is
// public at mcap.dev/spec): magic, header, then chunks of schema, channel and message records, each chunk
// followed by one message index per channel in it; data end with the data section's CRC-32; a summary
// (schemas, channels, chunk indexes, statistics) grouped by opcode with its summary offsets; the footer with
// the summary's CRC-32; magic. Chunks are stored plain or zstd-compressed; each carries the CRC-32 of its
// uncompressed records. Written to any std::ostream (through writeFileAtomically for files); the bytes
// depend only on the calls made.
#pragma once

#include "core/crc32.hpp"

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace adit::io {

enum class McapCompression { None, Zstd };

struct McapOptions {
  std::string profile;                 // "" (no well-known profile: adit writes JSON messages)
  std::string library = "adit";
  std::size_t chunk_bytes = 4u << 20;  // a chunk is closed once its uncompressed records reach this size
  McapCompression compression = McapCompression::Zstd;
  int zstd_level = 3;
};

struct McapStatistics {
  std::uint64_t messages = 0;
  std::uint32_t chunks = 0;
  std::uint64_t start_ns = 0, end_ns = 0;  // log times of the earliest and latest message (0 without any)
  std::map<std::uint16_t, std::uint64_t> per_channel;
};

class McapWriter {
 public:
  // Writes the magic and the header at once. Throws std::runtime_error when the stream fails.
  McapWriter(std::ostream& out, McapOptions options = {});
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Ids count from 1 in the order of the calls. encoding: "jsonschema", "" (none), ...
  std::uint16_t addSchema(const std::string& name, const std::string& encoding, const std::string& data);
  // schema_id 0: messages without a schema. message_encoding: "json", ...
  std::uint16_t addChannel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                           const std::map<std::string, std::string>& metadata = {});
  // One message; its sequence is the channel's count of messages before it. Times in nanoseconds.
  void write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             const std::string& data);
  // Closes the last chunk and writes data end, summary, summary offsets, footer and magic. Call once.
  void finish();

  const McapStatistics& statistics() const { return stats_; }

 private:
  struct ChunkIndex {
    std::uint64_t start_ns = 0, end_ns = 0, offset = 0, length = 0, compressed = 0, uncompressed = 0;
    std::map<std::uint16_t, std::uint64_t> message_index_offsets;
    std::uint64_t message_index_length = 0;
  };
  struct OpenChunk {
    std::string records;
    std::uint64_t start_ns = 0, end_ns = 0;
    bool has_messages = false;
    // Per channel: (log time, offset of the message record in `records`).
    std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> index;
  };

  void emit(const std::string& bytes);
  void flushChunk();
  std::string chunkRecord(const std::string& stored) const;
  void writeSummary();

  std::ostream& out_;
  McapOptions options_;
  std::uint64_t offset_ = 0;
  bool finished_ = false;
  bool in_data_section_ = true;
  Crc32 data_crc_;  // every byte before the data end record, magic and header included
  std::vector<std::string> schema_records_, channel_records_;
  std::map<std::uint16_t, std::uint32_t> next_sequence_;
  std::vector<ChunkIndex> chunk_indexes_;
  OpenChunk chunk_;
  McapStatistics stats_;
};

}  // namespace adit::io
