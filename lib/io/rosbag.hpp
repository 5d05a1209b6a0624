// ROS 1 bag files (format 2.0) read without ROS: the container only (records, chunks, connections);
// ros_messages.hpp decodes the message bodies.
//
// Layout: "#ROSBAG V2.0\n", then records. A record is a header (uint32 length, then fields, each
// uint32 length + "name=value") and data (uint32 length + bytes). The header field `op` says what it is:
// 0x03 bag header, 0x05 chunk (fields compression = none|bz2|lz4, size = uncompressed bytes; its data
// holds connection and message records), 0x07 connection (conn, topic; data = a header with type,
// md5sum, message_definition), 0x02 message (conn, time = uint32 secs + uint32 nsecs), 0x04 index and
// 0x06 chunk info (chunks are read front to back, so an unindexed bag from an interrupted recording
// reads too; the chunk infos only serve to resynchronise, below). Connection records sit in the chunks
// and again after the last chunk; the reader collects the trailing copies first, so a message whose
// chunk-local connection record was lost still finds its topic.
//
// Bad input: every length is checked against the bytes present before anything is allocated. A chunk
// that does not decompress, decompresses to another size than it declares, uses an unknown compression
// or holds malformed records is lost alone (counted in chunks_lost, with the reason in last_error);
// the next chunk is read. A record header that breaks the framing of the file itself (the chain of
// top-level lengths) is skipped to the next chunk the index lists (chunks_lost counts the chunks
// skipped, resyncs the jumps); without an index entry beyond it the reading ends there: truncated is
// set. Only a file that is not a bag at all (missing version line or bag header) throws ReadError.
#pragma once

#include <cstdint>
#include <cstdio>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "io/io_error.hpp"

namespace adit::io {

struct BagConnection {
  std::uint32_t id = 0;
  std::string topic, type, md5sum, message_definition;
};

struct BagMessage {
  std::uint32_t conn = 0;
  std::int64_t time_ns = 0;  // record time (when the recorder received it), ns since 1970
  std::vector<std::uint8_t> data;  // the ROS-serialised message
};

struct BagReadStats {
  std::int64_t chunks = 0;        // chunk records met
  std::int64_t chunks_lost = 0;   // chunks skipped as corrupt (reason in last_error)
  std::int64_t messages = 0;      // message records returned
  std::int64_t unknown_conn = 0;  // messages of a connection never defined (skipped)
  std::int64_t resyncs = 0;       // jumps over broken framing to the next indexed chunk
  bool truncated = false;         // the file's record chain broke before its end
  std::string last_error;
};

// The largest chunk (uncompressed) accepted. rosbag writes 768 KiB chunks by default; 256 MiB leaves room
// for a recorder configured with huge chunks and bounds what a crafted size field makes us hold.
constexpr std::uint64_t kMaxBagChunkBytes = 256ull << 20;

class BagReader {
 public:
  // Opens `path` and reads its version line, bag header and trailing connection records.
  // Throws ReadError if the file cannot be opened or is not a bag format 2.0 file.
  explicit BagReader(const std::string& path);
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  // Next message in file order; false at the end (or where the file breaks: stats().truncated).
  bool next(BagMessage& message);
  // Connections by id, known so far (all of them once the whole file was read).
  const std::map<std::uint32_t, BagConnection>& connections() const { return connections_; }
  const BagReadStats& stats() const { return stats_; }
  // Bytes consumed / file size.
  double progress() const;
  const std::string& path() const { return path_; }

 private:
  struct Record;
  bool readTopLevel(Record& record);
  void readTrailingConnections(std::uint64_t index_pos);
  void loadChunk(const Record& chunk);
  void breakAt(const std::string& why);
  bool resynchronise();

  std::string path_;
  std::FILE* file_ = nullptr;
  std::uint64_t size_ = 0, pos_ = 0;
  std::vector<std::uint64_t> chunk_positions_;  // from the index's chunk infos, ascending
  std::map<std::uint32_t, BagConnection> connections_;
  std::deque<BagMessage> pending_;  // messages of the current chunk
  BagReadStats stats_;
  bool done_ = false;
};

}  // namespace adit::io
