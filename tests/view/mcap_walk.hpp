// A minimal MCAP reader for the tests: walks a file's records (and a chunk's, decompressing zstd), so that
// tests can check offsets, lengths, CRCs and counts against the specification without trusting the writer.
#pragma once

#include "core/crc32.hpp"

#include <zstd.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace adit::test {

struct McapRecord {
  std::uint8_t op = 0;
  std::uint64_t offset = 0;  // of the opcode, from the start of the walked bytes
  std::string content;
};

class McapCursor {
 public:
  explicit McapCursor(const std::string& bytes, std::size_t pos = 0) : bytes_(bytes), pos_(pos) {}
  template <class T>
  T num() {
    need(sizeof(T));
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<std::uint64_t>(static_cast<std::uint8_t>(bytes_[pos_ + i])) << (8 * i);
    pos_ += sizeof(T);
    return static_cast<T>(v);
  }
  std::string take(std::size_t n) {
    need(n);
    std::string s = bytes_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  std::string str() { return take(num<std::uint32_t>()); }
  bool done() const { return pos_ >= bytes_.size(); }
  std::size_t pos() const { return pos_; }

 private:
  void need(std::size_t n) const {
    if (pos_ + n > bytes_.size()) throw std::runtime_error("MCAP walk: past the end");
  }
  const std::string& bytes_;
  std::size_t pos_;
};

// Records of `bytes` from `begin` to `end` (a whole section, or a chunk's records).
inline std::vector<McapRecord> walkRecords(const std::string& bytes, std::size_t begin, std::size_t end) {
  std::vector<McapRecord> out;
  const std::string view = bytes.substr(0, end);
  McapCursor c(view, begin);
  while (!c.done()) {
    McapRecord r;
    r.offset = c.pos();
    r.op = c.num<std::uint8_t>();
    r.content = c.take(c.num<std::uint64_t>());
    out.push_back(std::move(r));
  }
  return out;
}

struct McapChunk {
  std::uint64_t start_ns = 0, end_ns = 0, uncompressed_size = 0;
  std::uint32_t crc = 0;
  std::string compression, records;  // records decompressed
};

inline McapChunk decodeChunk(const std::string& content) {
  McapCursor c(content);
  McapChunk chunk;
  chunk.start_ns = c.num<std::uint64_t>();
  chunk.end_ns = c.num<std::uint64_t>();
  chunk.uncompressed_size = c.num<std::uint64_t>();
  chunk.crc = c.num<std::uint32_t>();
  chunk.compression = c.str();
  const std::string stored = c.take(c.num<std::uint64_t>());
  if (chunk.compression == "zstd") {
    chunk.records.resize(chunk.uncompressed_size);
    const std::size_t n = ZSTD_decompress(chunk.records.data(), chunk.records.size(), stored.data(), stored.size());
    if (ZSTD_isError(n) || n != chunk.uncompressed_size) throw std::runtime_error("MCAP walk: zstd");
  } else {
    chunk.records = stored;
  }
  return chunk;
}

}  // namespace adit::test
