// The MCAP writer against the specification, read back with the tests' own record walker: structure,
// offsets and lengths of every index, CRCs, statistics; both chunk encodings; determinism.
#include "io/mcap_writer.hpp"

#include "mcap_walk.hpp"

#include <gtest/gtest.h>

#include <map>
#include <sstream>

namespace {

using adit::io::McapCompression;
using adit::io::McapOptions;
using adit::io::McapWriter;
using adit::test::decodeChunk;
using adit::test::McapCursor;
using adit::test::McapRecord;
using adit::test::walkRecords;

const std::string kMagic("\x89MCAP0\r\n", 8);

// 3 channels (two share a schema, one has none), 250 messages with sizes that vary, small chunks.
std::string writeSample(McapCompression compression, std::size_t chunk_bytes) {
  std::ostringstream out;
  McapOptions options;
  options.compression = compression;
  options.chunk_bytes = chunk_bytes;
  McapWriter w(out, options);
  const auto pose = w.addSchema("foxglove.FrameTransform", "jsonschema", R"({"type":"object"})");
  const auto a = w.addChannel(pose, "/tf", "json", {{"frame", "world"}});
  const auto b = w.addChannel(pose, "/tf_gt", "json");
  const auto c = w.addChannel(0, "/status", "json");
  for (int i = 0; i < 250; ++i) {
    const auto t = static_cast<std::uint64_t>(1000000000 + i * 100000000LL);
    const auto channel = i % 5 == 0 ? c : (i % 2 ? a : b);
    w.write(channel, t, t - 7, "{\"i\":" + std::to_string(i) + ",\"pad\":\"" + std::string(static_cast<std::size_t>(i % 37), 'x') + "\"}");
  }
  w.finish();
  return out.str();
}

struct Parsed {
  std::vector<McapRecord> records;  // top level, between the magics
  std::uint64_t summary_start = 0, summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
};

Parsed parse(const std::string& file) {
  EXPECT_EQ(file.substr(0, 8), kMagic);
  EXPECT_EQ(file.substr(file.size() - 8), kMagic);
  Parsed p;
  p.records = walkRecords(file, 8, file.size() - 8);
  const McapRecord& footer = p.records.back();
  EXPECT_EQ(footer.op, 0x02);
  McapCursor c(footer.content);
  p.summary_start = c.num<std::uint64_t>();
  p.summary_offset_start = c.num<std::uint64_t>();
  p.summary_crc = c.num<std::uint32_t>();
  return p;
}

const McapRecord& at(const Parsed& p, std::uint64_t offset) {
  for (const auto& r : p.records)
    if (r.offset == offset) return r;
  throw std::runtime_error("no record at offset " + std::to_string(offset));
}

void checkFile(const std::string& file, const std::string& compression) {
  const Parsed p = parse(file);
  ASSERT_GE(p.records.size(), 4u);
  EXPECT_EQ(p.records.front().op, 0x01);

  // Data end: right before the summary, its CRC over every byte before it.
  std::size_t data_end = 0;
  while (p.records[data_end].op != 0x0F) ++data_end;
  const McapRecord& end_record = p.records[data_end];
  EXPECT_EQ(end_record.offset + 1 + 8 + 4, p.summary_start);
  EXPECT_EQ(McapCursor(end_record.content).num<std::uint32_t>(), adit::crc32(file.data(), end_record.offset));
  // Footer CRC: summary start through the footer's summary_offset_start field.
  const std::size_t footer_offset = file.size() - 8 - (1 + 8 + 20);
  EXPECT_EQ(p.summary_crc, adit::crc32(file.data() + p.summary_start, footer_offset + 1 + 8 + 16 - p.summary_start));

  // Chunks: CRC of the uncompressed records, and every message index entry points at its message.
  std::map<std::uint16_t, std::uint64_t> counted;
  std::map<std::uint64_t, std::uint64_t> chunk_lengths;
  std::uint64_t messages_in_chunks = 0;
  for (std::size_t i = 0; i < data_end; ++i) {
    if (p.records[i].op != 0x06) continue;
    const auto chunk = decodeChunk(p.records[i].content);
    EXPECT_EQ(chunk.compression, compression);
    EXPECT_EQ(chunk.crc, adit::crc32(chunk.records.data(), chunk.records.size()));
    chunk_lengths[p.records[i].offset] = 1 + 8 + p.records[i].content.size();
    for (const auto& r : walkRecords(chunk.records, 0, chunk.records.size())) {
      if (r.op != 0x05) continue;
      McapCursor m(r.content);
      ++counted[m.num<std::uint16_t>()];
      ++messages_in_chunks;
      m.num<std::uint32_t>();
      const auto log_time = m.num<std::uint64_t>();
      EXPECT_GE(log_time, chunk.start_ns);
      EXPECT_LE(log_time, chunk.end_ns);
    }
    for (std::size_t j = i + 1; j < p.records.size() && p.records[j].op == 0x07; ++j) {
      McapCursor mi(p.records[j].content);
      const auto channel = mi.num<std::uint16_t>();
      const std::string entries = mi.str();
      McapCursor e(entries);
      while (!e.done()) {
        const auto time = e.num<std::uint64_t>();
        const auto offset = e.num<std::uint64_t>();
        McapCursor m(chunk.records, static_cast<std::size_t>(offset));
        ASSERT_EQ(m.num<std::uint8_t>(), 0x05);
        m.num<std::uint64_t>();
        EXPECT_EQ(m.num<std::uint16_t>(), channel);
        m.num<std::uint32_t>();
        EXPECT_EQ(m.num<std::uint64_t>(), time);
      }
    }
  }
  EXPECT_EQ(messages_in_chunks, 250u);

  // Summary offsets name groups of one opcode each; chunk indexes point at chunks; statistics agree.
  std::map<std::uint8_t, int> groups;
  for (const auto& r : p.records) {
    if (r.offset < p.summary_offset_start || r.op != 0x0E) continue;
    McapCursor c(r.content);
    const auto op = c.num<std::uint8_t>();
    const auto start = c.num<std::uint64_t>();
    const auto length = c.num<std::uint64_t>();
    ++groups[op];
    for (const auto& g : p.records) {
      if (g.offset >= start && g.offset < start + length) {
        EXPECT_EQ(g.op, op);
      }
    }
  }
  EXPECT_EQ(groups, (std::map<std::uint8_t, int>{{0x03, 1}, {0x04, 1}, {0x08, 1}, {0x0B, 1}}));
  int chunk_indexes = 0;
  for (const auto& r : p.records) {
    if (r.offset < p.summary_start) continue;
    McapCursor c(r.content);
    if (r.op == 0x08) {
      ++chunk_indexes;
      c.num<std::uint64_t>();
      c.num<std::uint64_t>();
      const auto offset = c.num<std::uint64_t>();
      EXPECT_EQ(at(p, offset).op, 0x06);
      EXPECT_EQ(c.num<std::uint64_t>(), chunk_lengths.at(offset));
      const std::string offsets = c.str();
      McapCursor o(offsets);
      while (!o.done()) {
        o.num<std::uint16_t>();
        EXPECT_EQ(at(p, o.num<std::uint64_t>()).op, 0x07);
      }
    } else if (r.op == 0x0B) {
      EXPECT_EQ(c.num<std::uint64_t>(), 250u);
      EXPECT_EQ(c.num<std::uint16_t>(), 1u);
      EXPECT_EQ(c.num<std::uint32_t>(), 3u);
      c.num<std::uint32_t>();
      c.num<std::uint32_t>();
      EXPECT_EQ(c.num<std::uint32_t>(), chunk_lengths.size());
      EXPECT_EQ(c.num<std::uint64_t>(), 1000000000u);
      EXPECT_EQ(c.num<std::uint64_t>(), 1000000000ULL + 249ULL * 100000000ULL);
      const std::string per_channel = c.str();
      McapCursor pc(per_channel);
      std::map<std::uint16_t, std::uint64_t> stated;
      while (!pc.done()) {
        const auto id = pc.num<std::uint16_t>();
        stated[id] = pc.num<std::uint64_t>();
      }
      EXPECT_EQ(stated, counted);
    }
  }
  EXPECT_EQ(chunk_indexes, static_cast<int>(chunk_lengths.size()));
}

TEST(McapWriter, UncompressedChunksFollowTheSpecification) {
  const std::string file = writeSample(McapCompression::None, 2000);
  checkFile(file, "");
  EXPECT_GT(parse(file).records.size(), 10u);  // several chunks
}

TEST(McapWriter, ZstdChunksFollowTheSpecification) { checkFile(writeSample(McapCompression::Zstd, 2000), "zstd"); }

TEST(McapWriter, OneChunkWhenChunksAreLarge) {
  const std::string file = writeSample(McapCompression::None, 1u << 30);
  int chunks = 0;
  for (const auto& r : parse(file).records) chunks += r.op == 0x06;
  EXPECT_EQ(chunks, 1);
  checkFile(file, "");
}

TEST(McapWriter, SameCallsSameBytes) {
  EXPECT_EQ(writeSample(McapCompression::Zstd, 3000), writeSample(McapCompression::Zstd, 3000));
}

TEST(McapWriter, EmptyFileHasHeaderDataEndAndFooter) {
  std::ostringstream out;
  McapWriter w(out);
  w.finish();
  const Parsed p = parse(out.str());
  std::vector<std::uint8_t> ops;
  for (const auto& r : p.records) ops.push_back(r.op);
  // Header, data end, statistics, its summary offset, footer.
  EXPECT_EQ(ops, (std::vector<std::uint8_t>{0x01, 0x0F, 0x0B, 0x0E, 0x02}));
}

TEST(McapWriter, RefusesUnknownChannelsAndSchemas) {
  std::ostringstream out;
  McapWriter w(out);
  EXPECT_THROW(w.addChannel(3, "/x", "json"), std::runtime_error);
  EXPECT_THROW(w.write(1, 0, 0, "{}"), std::runtime_error);
}

}  // namespace
