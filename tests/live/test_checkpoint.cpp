// The checkpoint file format: round trip, and every kind of bad file refused with a reason, never a crash.
#include "core/byte_codec.hpp"
#include "io/atomic_file.hpp"
#include "node_harness.hpp"
#include "runtime/checkpoint.hpp"

#include <gtest/gtest.h>

#include <fstream>

using adit::runtime::LoadedCheckpoint;
using adit::runtime::loadCheckpoint;
using adit::runtime::saveCheckpoint;

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void writeFile(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

TEST(Checkpoint, RoundTrip) {
  adit::test::TempFolder dir;
  const std::string path = dir.file("x.ckpt");
  const std::string payload("state\0with\0zeros", 16);
  saveCheckpoint(path, "odometry", "run-1", payload);
  const LoadedCheckpoint c = loadCheckpoint(path, "odometry", "run-1");
  ASSERT_EQ(c.status, LoadedCheckpoint::Status::kLoaded) << c.error;
  EXPECT_EQ(c.payload, payload);
}

TEST(Checkpoint, MissingIsAFreshStartNotAnError) {
  adit::test::TempFolder dir;
  const LoadedCheckpoint c = loadCheckpoint(dir.file("none.ckpt"), "odometry", "run-1");
  EXPECT_EQ(c.status, LoadedCheckpoint::Status::kMissing);
  EXPECT_TRUE(c.error.empty());
}

TEST(Checkpoint, RefusesOtherRunKindTruncationAndCorruption) {
  adit::test::TempFolder dir;
  const std::string path = dir.file("x.ckpt");
  saveCheckpoint(path, "mapper", "run-1", std::string(1000, 'p'));
  const auto refused = [&](const std::string& kind, const std::string& run, const std::string& word) {
    const LoadedCheckpoint c = loadCheckpoint(path, kind, run);
    EXPECT_EQ(c.status, LoadedCheckpoint::Status::kRefused);
    EXPECT_NE(c.error.find(word), std::string::npos) << c.error;
  };
  refused("mapper", "run-2", "run-1");
  refused("odometry", "run-1", "mapper");
  const std::string good = readFile(path);
  for (std::size_t cut : {std::size_t{0}, std::size_t{5}, std::size_t{20}, good.size() / 2, good.size() - 1}) {
    writeFile(path, good.substr(0, cut));
    const LoadedCheckpoint c = loadCheckpoint(path, "mapper", "run-1");
    EXPECT_EQ(c.status, LoadedCheckpoint::Status::kRefused) << "cut at " << cut;
    EXPECT_FALSE(c.error.empty());
  }
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  writeFile(path, flipped);
  refused("mapper", "run-1", "checksum");
  std::string huge_count = good;  // the kind's length field claims 2^62 bytes
  huge_count[12 + 7] = 0x40;
  writeFile(path, huge_count);
  EXPECT_EQ(loadCheckpoint(path, "mapper", "run-1").status, LoadedCheckpoint::Status::kRefused);
}

TEST(Checkpoint, UnwritablePathKeepsThePreviousFile) {
  adit::test::TempFolder dir;
  EXPECT_THROW(saveCheckpoint(dir.file("missing/x.ckpt"), "odometry", "run-1", "p"), std::exception);
  const std::string path = dir.file("x.ckpt");
  saveCheckpoint(path, "odometry", "run-1", "first");
  std::filesystem::create_directory(adit::io::atomicTempPath(path));  // the temp file cannot be made
  EXPECT_THROW(saveCheckpoint(path, "odometry", "run-1", "second"), std::exception);
  EXPECT_EQ(loadCheckpoint(path, "odometry", "run-1").payload, "first");
}

TEST(ByteReader, NeverReadsPastTheEndNorAllocatesFromACount) {
  adit::ByteWriter w;
  w.put<std::uint64_t>(~0ull);  // a count no buffer can hold
  adit::ByteReader r(w.bytes());
  EXPECT_TRUE(r.getPoints<Eigen::Vector3f>().empty());
  EXPECT_FALSE(r.ok());
  adit::ByteReader short_read(std::string(3, 'x'));
  short_read.get<double>();
  EXPECT_FALSE(short_read.ok());
}

}  // namespace
