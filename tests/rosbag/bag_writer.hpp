// Test helper: writes ROS 1 bag format 2.0 files from scratch (none / bz2 / lz4 chunks, connection and
// message records, trailing connection copies and the bag header's index_pos), and serialises the two
// message types adit reads, so tests know exactly what a bag holds. Also used for the fuzz seeds.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace adit::test {

using Bytes = std::vector<std::uint8_t>;

class BagWriter {
 public:
  // compression: "none", "bz2" or "lz4" (LZ4 frame format, as roslz4 writes it).
  // header_padding: rosbag pads the bag header record to 4096 bytes; the fuzz seeds use 0 to stay small.
  explicit BagWriter(std::string compression, std::size_t header_padding = 4096)
      : compression_(std::move(compression)), padding_(header_padding) {}
  void addConnection(std::uint32_t id, const std::string& topic, const std::string& type);
  // Appends to the open chunk; the connection's record goes into the chunk before its first message.
  void addMessage(std::uint32_t conn, std::int64_t time_ns, const Bytes& data);
  // Closes the open chunk (no-op if empty). Returns the byte range [begin, end) of the chunk's data.
  std::pair<std::size_t, std::size_t> endChunk();
  // The whole file: version line, bag header, chunks, trailing connections and chunk infos (the index).
  std::string finish();
  // File offset of each chunk record (valid after finish()).
  const std::vector<std::uint64_t>& chunkPositions() const { return chunk_pos_; }

 private:
  struct Conn {
    std::uint32_t id;
    std::string topic, type;
  };
  std::string connectionRecord(const Conn& c) const;
  std::string bagHeaderRecord(std::uint64_t index_pos) const;
  std::string compression_;
  std::size_t padding_;
  std::vector<Conn> conns_;
  std::vector<bool> in_chunk_;
  std::string chunk_, body_;
  int chunks_ = 0;
  std::vector<std::uint64_t> chunk_pos_;
};

// One field of a PointCloud2 (datatype: 1 INT8 .. 8 FLOAT64, as sensor_msgs/PointField).
struct CloudField {
  std::string name;
  std::uint32_t offset;
  std::uint8_t datatype;
};

// sensor_msgs/PointCloud2 with height 1 (or `height` rows, each padded by `row_padding` bytes).
Bytes pointCloud2(std::uint32_t sec, std::uint32_t nsec, const std::vector<CloudField>& fields, std::uint32_t point_step,
                  const Bytes& points, std::uint32_t height = 1, std::uint32_t row_padding = 0);
// sensor_msgs/Imu; without orientation the covariance[0] is -1.
Bytes imuMessage(std::uint32_t sec, std::uint32_t nsec, const ImuSample& s);

// Appends a little-endian value to a byte buffer.
template <typename T>
void put(Bytes& b, T v) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
  b.insert(b.end(), p, p + sizeof(T));
}

}  // namespace adit::test
