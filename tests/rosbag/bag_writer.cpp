#include "bag_writer.hpp"

#include <bzlib.h>
#include <lz4frame.h>

#include <cstring>
#include <stdexcept>

namespace adit::test {
namespace {

std::string u32(std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }
std::string u64(std::uint64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); }
std::string fieldOf(const std::string& name, const std::string& value) { return u32(static_cast<std::uint32_t>(name.size() + 1 + value.size())) + name + "=" + value; }
std::string record(const std::string& header, const std::string& data) { return u32(static_cast<std::uint32_t>(header.size())) + header + u32(static_cast<std::uint32_t>(data.size())) + data; }

std::string compress(const std::string& how, const std::string& plain) {
  if (how == "none") return plain;
  if (how == "bz2") {
    unsigned int size = static_cast<unsigned int>(plain.size() * 1.02 + 600);
    std::string out(size, '\0');
    if (BZ2_bzBuffToBuffCompress(out.data(), &size, const_cast<char*>(plain.data()), static_cast<unsigned int>(plain.size()), 9, 0, 30) != BZ_OK)
      throw std::runtime_error("bz2 compression failed");
    out.resize(size);
    return out;
  }
  if (how == "lz4") {
    // The frame options roslz4 (rosbag's lz4 writer) uses: independent 1 MB blocks, no block checksums, a
    // content checksum, no content size.
    LZ4F_preferences_t prefs{};
    prefs.frameInfo.blockSizeID = LZ4F_max1MB;
    prefs.frameInfo.blockMode = LZ4F_blockIndependent;
    prefs.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
    std::string out(LZ4F_compressFrameBound(plain.size(), &prefs), '\0');
    const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), plain.data(), plain.size(), &prefs);
    if (LZ4F_isError(n)) throw std::runtime_error("lz4 compression failed");
    out.resize(n);
    return out;
  }
  return plain;  // an unknown name: the test wants a chunk the reader cannot decompress
}

std::string header(std::uint32_t seq, std::uint32_t sec, std::uint32_t nsec) {
  return u32(seq) + u32(sec) + u32(nsec) + u32(4) + "base";
}

}  // namespace

void BagWriter::addConnection(std::uint32_t id, const std::string& topic, const std::string& type) {
  conns_.push_back({id, topic, type});
  in_chunk_.push_back(false);
}

std::string BagWriter::connectionRecord(const Conn& c) const {
  const std::string h = fieldOf("op", "\x07") + fieldOf("conn", u32(c.id)) + fieldOf("topic", c.topic);
  const std::string d = fieldOf("topic", c.topic) + fieldOf("type", c.type) + fieldOf("md5sum", std::string(32, '0')) +
                        fieldOf("message_definition", "# test\n");
  return record(h, d);
}

void BagWriter::addMessage(std::uint32_t conn, std::int64_t time_ns, const Bytes& data) {
  for (std::size_t i = 0; i < conns_.size(); ++i)
    if (conns_[i].id == conn && !in_chunk_[i]) {
      chunk_ += connectionRecord(conns_[i]);
      in_chunk_[i] = true;
    }
  const auto sec = static_cast<std::uint32_t>(time_ns / 1000000000), nsec = static_cast<std::uint32_t>(time_ns % 1000000000);
  const std::string h = fieldOf("op", "\x02") + fieldOf("conn", u32(conn)) + fieldOf("time", u32(sec) + u32(nsec));
  chunk_ += record(h, std::string(data.begin(), data.end()));
}

// The bag header record: its data pads header + data to padding_ bytes, so its size does not depend on index_pos.
std::string BagWriter::bagHeaderRecord(std::uint64_t index_pos) const {
  const std::string h = fieldOf("chunk_count", u32(static_cast<std::uint32_t>(chunks_))) +
                        fieldOf("conn_count", u32(static_cast<std::uint32_t>(conns_.size()))) +
                        fieldOf("index_pos", u64(index_pos)) + fieldOf("op", "\x03");
  return record(h, std::string(padding_ > h.size() ? padding_ - h.size() : 0, ' '));
}

std::pair<std::size_t, std::size_t> BagWriter::endChunk() {
  if (chunk_.empty()) return {0, 0};
  const std::string data = compress(compression_, chunk_);
  const std::string h = fieldOf("compression", compression_) + fieldOf("op", "\x05") + fieldOf("size", u32(static_cast<std::uint32_t>(chunk_.size())));
  chunk_pos_.push_back(13 + bagHeaderRecord(0).size() + body_.size());
  const std::size_t begin = chunk_pos_.back() + 4 + h.size() + 4;
  body_ += record(h, data);
  chunk_.clear();
  in_chunk_.assign(conns_.size(), false);
  ++chunks_;
  return {begin, begin + data.size()};
}

std::string BagWriter::finish() {
  endChunk();
  const std::uint64_t index_pos = 13 + bagHeaderRecord(0).size() + body_.size();
  std::string out = "#ROSBAG V2.0\n" + bagHeaderRecord(index_pos) + body_;
  for (const Conn& c : conns_) out += connectionRecord(c);
  for (const std::uint64_t pos : chunk_pos_)  // chunk infos without the per-connection counts (adit ignores them)
    out += record(fieldOf("op", "\x06") + fieldOf("ver", u32(1)) + fieldOf("chunk_pos", u64(pos)) +
                      fieldOf("start_time", u64(0)) + fieldOf("end_time", u64(0)) + fieldOf("count", u32(0)),
                  "");
  return out;
}

Bytes pointCloud2(std::uint32_t sec, std::uint32_t nsec, const std::vector<CloudField>& fields, std::uint32_t point_step,
                  const Bytes& points, std::uint32_t height, std::uint32_t row_padding) {
  const std::string h = header(7, sec, nsec);
  Bytes b(h.begin(), h.end());
  const auto per_row = static_cast<std::uint32_t>(points.size() / point_step / height);
  put<std::uint32_t>(b, height);
  put<std::uint32_t>(b, per_row);
  put<std::uint32_t>(b, static_cast<std::uint32_t>(fields.size()));
  for (const CloudField& f : fields) {
    put<std::uint32_t>(b, static_cast<std::uint32_t>(f.name.size()));
    b.insert(b.end(), f.name.begin(), f.name.end());
    put<std::uint32_t>(b, f.offset);
    put<std::uint8_t>(b, f.datatype);
    put<std::uint32_t>(b, 1);
  }
  put<std::uint8_t>(b, 0);  // little-endian
  put<std::uint32_t>(b, point_step);
  const std::uint32_t row_step = per_row * point_step + row_padding;
  put<std::uint32_t>(b, row_step);
  put<std::uint32_t>(b, row_step * height);
  for (std::uint32_t r = 0; r < height; ++r) {
    const auto* row = points.data() + std::size_t{r} * per_row * point_step;
    b.insert(b.end(), row, row + std::size_t{per_row} * point_step);
    b.insert(b.end(), row_padding, 0xAB);
  }
  put<std::uint8_t>(b, 1);  // is_dense
  return b;
}

Bytes imuMessage(std::uint32_t sec, std::uint32_t nsec, const ImuSample& s) {
  const std::string h = header(3, sec, nsec);
  Bytes b(h.begin(), h.end());
  const Eigen::Quaterniond q = s.orientation.value_or(Eigen::Quaterniond(0, 0, 0, 0));
  for (double v : {q.x(), q.y(), q.z(), q.w()}) put(b, v);
  for (int i = 0; i < 9; ++i) put(b, i == 0 && !s.orientation ? -1.0 : 0.01);
  for (int i = 0; i < 3; ++i) put(b, s.gyro[i]);
  for (int i = 0; i < 9; ++i) put(b, 0.001);
  for (int i = 0; i < 3; ++i) put(b, s.accel[i]);
  for (int i = 0; i < 9; ++i) put(b, 0.02);
  return b;
}

}  // namespace adit::test
