// Test helper: bags written in memory through the library's writer (io/rosbag_writer.hpp), so tests know
// exactly what a bag holds and where its chunks lie (to damage them). Also used for the fuzz seeds.
#pragma once

#include <cstdint>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "io/ros_encode.hpp"
#include "io/rosbag_writer.hpp"

namespace adit::test {

using Bytes = std::vector<std::uint8_t>;

class BagWriter {
 public:
  // compression: "none", "bz2", "lz4", or any other four-letter name (e.g. "zstd"): the chunks are then stored
  // uncompressed under that name, a bag whose chunks the reader cannot decompress.
  // header_padding: rosbag pads the bag header record to 4096 bytes; the fuzz seeds use 0 to stay small.
  explicit BagWriter(const std::string& compression, std::size_t header_padding = 4096);
  // `type`: sensor_msgs/PointCloud2 and sensor_msgs/Imu get their real md5sums and definitions.
  void addConnection(std::uint32_t id, const std::string& topic, const std::string& type);
  void addMessage(std::uint32_t conn, std::int64_t time_ns, const Bytes& data) { writer_->write(conn, time_ns, data); }
  // Closes the open chunk (no-op if empty). Returns the byte range [begin, end) of the chunk's data.
  std::pair<std::size_t, std::size_t> endChunk() { return writer_->endChunk(); }
  // The whole file.
  std::string finish();
  // File offset of each chunk record.
  const std::vector<std::uint64_t>& chunkPositions() const { return writer_->chunkPositions(); }

 private:
  std::string unknown_compression_;
  std::ostringstream out_;
  std::unique_ptr<io::RosbagWriter> writer_;
};

using CloudField = io::RosPointField;

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
