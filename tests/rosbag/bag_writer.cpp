#include "bag_writer.hpp"

#include <stdexcept>

namespace adit::test {

BagWriter::BagWriter(const std::string& compression, std::size_t header_padding) {
  io::RosbagWriter::Options options;
  options.header_padding = header_padding;
  options.chunk_bytes = std::size_t{1} << 30;  // chunks end where the test says (endChunk)
  options.compression = compression;
  if (compression != "none" && compression != "bz2" && compression != "lz4") {
    if (compression.size() != 4) throw std::invalid_argument("an unknown compression name must have 4 letters");
    unknown_compression_ = compression;  // same length as "none": patched over it in finish()
    options.compression = "none";
  }
  writer_ = std::make_unique<io::RosbagWriter>(out_, options);
}

void BagWriter::addConnection(std::uint32_t id, const std::string& topic, const std::string& type) {
  if (type == io::pointCloud2Type().name) return writer_->addConnection(id, topic, io::pointCloud2Type());
  if (type == io::imuType().name) return writer_->addConnection(id, topic, io::imuType());
  writer_->addConnection(id, topic, {type, std::string(32, '0'), "# test\n"});
}

std::string BagWriter::finish() {
  writer_->finish();
  std::string bag = out_.str();
  if (!unknown_compression_.empty())
    for (std::size_t at = bag.find("compression=none"); at != std::string::npos; at = bag.find("compression=none", at + 1))
      bag.replace(at + 12, 4, unknown_compression_);
  return bag;
}

Bytes pointCloud2(std::uint32_t sec, std::uint32_t nsec, const std::vector<CloudField>& fields, std::uint32_t point_step,
                  const Bytes& points, std::uint32_t height, std::uint32_t row_padding) {
  return io::encodePointCloud2({7, {sec, nsec}, "base"}, fields, point_step, points, height, row_padding);
}

Bytes imuMessage(std::uint32_t sec, std::uint32_t nsec, const ImuSample& s) { return io::encodeImu({3, {sec, nsec}, "imu"}, s); }

}  // namespace adit::test
