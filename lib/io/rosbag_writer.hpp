// Writes ROS 1 bag files, format 2.0, as `rosbag record` does, without ROS: the version line, a bag header
// record padded to a fixed size (rewritten at the end with the index position), chunks (uncompressed, bz2 or
// lz4 frames as roslz4 writes them) each followed by its index-data records, then the connection records and
// the chunk-info records that make up the index. So `rosbag info` / `rosbag play` and adit's own reader
// (rosbag.hpp) both read what it writes. Streams to any seekable std::ostream: memory holds one chunk.
//
// Record layout (ROS wiki "Bags/Format/2.0"): header_len u32, header fields (field_len u32, "name=value"),
// data_len u32, data. Ops: 0x02 message data, 0x03 bag header, 0x04 index data, 0x05 chunk, 0x06 chunk
// info, 0x07 connection. Times are u32 seconds + u32 nanoseconds.
#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace adit::io {

// What a connection record tells a ROS reader about its message type.
struct RosMessageType {
  std::string name;        // "sensor_msgs/PointCloud2"
  std::string md5sum;      // 32 hex digits
  std::string definition;  // the full message definition, dependencies included
};

class RosbagWriter {
 public:
  struct Options {
    std::string compression = "none";     // "none", "bz2" or "lz4"
    std::size_t chunk_bytes = 768 * 1024; // a chunk is closed once its uncompressed data reaches this (rosbag's default)
    std::size_t header_padding = 4096;    // the bag header record's size, as rosbag pads it
  };

  // Writes the version line and a placeholder bag header. Throws std::invalid_argument for an unknown
  // compression, std::runtime_error when the stream fails.
  RosbagWriter(std::ostream& out, Options options);
  RosbagWriter(std::ostream& out) : RosbagWriter(out, Options{}) {}

  // `id` is the connection's number in the bag (unique; rosbag counts from 0).
  void addConnection(std::uint32_t id, const std::string& topic, const RosMessageType& type);
  // A serialised message at record time `time_ns` (nanoseconds since the epoch). Throws std::out_of_range
  // for an unknown connection.
  void write(std::uint32_t conn, std::int64_t time_ns, const std::uint8_t* data, std::size_t size);
  void write(std::uint32_t conn, std::int64_t time_ns, const std::vector<std::uint8_t>& data) {
    write(conn, time_ns, data.data(), data.size());
  }
  // Closes the open chunk now (no-op if it is empty). Returns the stream offsets [begin, end) of its stored
  // (compressed) data, e.g. for a test that damages it.
  std::pair<std::uint64_t, std::uint64_t> endChunk();
  // Closes the last chunk, writes the index and rewrites the bag header. Further writes are errors.
  void finish();

  // Stream offset of each chunk record written so far.
  const std::vector<std::uint64_t>& chunkPositions() const { return chunk_pos_; }
  std::int64_t messages() const { return messages_; }

 private:
  struct Connection {
    std::uint32_t id;
    std::string topic;
    RosMessageType type;
  };
  struct IndexEntry {
    std::int64_t time_ns;
    std::uint32_t offset;  // in the chunk's uncompressed data
  };
  struct ChunkInfo {
    std::uint64_t pos;
    std::int64_t start_ns, end_ns;
    std::map<std::uint32_t, std::uint32_t> counts;  // connection -> messages in the chunk
  };

  const Connection& connection(std::uint32_t id) const;
  std::string connectionRecord(const Connection& c) const;
  std::string bagHeaderRecord(std::uint64_t index_pos) const;
  void put(const std::string& bytes);

  std::ostream& out_;
  Options options_;
  std::uint64_t start_ = 0;  // stream offset of the version line
  std::uint64_t written_ = 0;
  std::vector<Connection> connections_;
  std::string chunk_;                                          // uncompressed records of the open chunk
  std::map<std::uint32_t, std::vector<IndexEntry>> chunk_index_;  // per connection, in the open chunk
  std::vector<bool> connection_in_chunk_;
  std::int64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0;
  std::vector<ChunkInfo> chunks_;
  std::vector<std::uint64_t> chunk_pos_;
  std::int64_t messages_ = 0;
  bool finished_ = false;
};

}  // namespace adit::io
