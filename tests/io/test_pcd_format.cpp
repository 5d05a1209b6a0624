// The PCD parser against hostile files: each case was a crash, a huge allocation or silent garbage with
// PCL's reader (issue 14). Every error must be a ReadError naming the file (and the line where there is one).
#include <gtest/gtest.h>

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <chrono>
#include <cstring>
#include <string>

#include "io/lzf.hpp"
#include "io/pcd.hpp"
#include "io/pcd_format.hpp"
#include "temp_dir.hpp"

namespace adit::io {
namespace {

using test::TempDir;

std::string header(const std::string& fields, const std::string& sizes, const std::string& types,
                   const std::string& counts, const std::string& width, const std::string& data,
                   const std::string& height = "1") {
  return "VERSION 0.7\nFIELDS " + fields + "\nSIZE " + sizes + "\nTYPE " + types + "\nCOUNT " + counts + "\nWIDTH " +
         width + "\nHEIGHT " + height + "\nVIEWPOINT 0 0 0 1 0 0 0\nDATA " + data + "\n";
}
const std::string kXyz = header("x y z", "4 4 4", "F F F", "1 1 1", "2", "ascii");

// The ReadError text for `bytes` saved as `name`, or "" if it parsed.
std::string errorFor(const TempDir& dir, const std::string& name, const std::string& bytes) {
  dir.write(name, bytes);
  try {
    readPcdScan(dir.file(name), PcdFolderConfig{}, 0, 0);
  } catch (const ReadError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.file(name)), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line: " << e.what();
    return e.what();
  }
  return "";
}

void expectError(const std::string& error, const std::string& part) {
  EXPECT_NE(error.find(part), std::string::npos) << "'" << error << "' should say '" << part << "'";
}

TEST(PcdFormat, AsciiGarbageIsAnErrorNamingTheLineNotZeros) {
  TempDir dir;
  expectError(errorFor(dir, "a.pcd", kXyz + "1 2 3\n4 five 6\n"), "line 11: 'five' is not a valid F32 value for field 'y'");
  expectError(errorFor(dir, "b.pcd", kXyz + "1 2 3\n4 5\n"), "line 11: 2 values, the header announces 3");
  expectError(errorFor(dir, "c.pcd", kXyz + "1 2 3\n"), "truncated: 1 of the announced 2 points");
  expectError(errorFor(dir, "d.pcd", kXyz + "1 2 3\n4 5 6\n7 8 9\n"), "line 12: more points than the header's 2");
  const std::string ints = header("x y z ring", "4 4 4 1", "F F F U", "1 1 1 1", "1", "ascii");
  expectError(errorFor(dir, "e.pcd", ints + "1 2 3 300\n"), "'300' is not a valid U8 value for field 'ring'");
  expectError(errorFor(dir, "f.pcd", ints + "1 2 3 -1\n"), "'-1' is not a valid U8 value");
  EXPECT_EQ(errorFor(dir, "g.pcd", ints + "1 2 3 255\n"), "");
}

TEST(PcdFormat, ShortBinaryBodyIsTruncatedNotAnOutOfBoundsRead) {
  TempDir dir;
  const std::string h = header("x y z", "4 4 4", "F F F", "1 1 1", "1000", "binary");
  expectError(errorFor(dir, "short.pcd", h + std::string(11, '\0')), "is truncated: 11 bytes of point data");
  EXPECT_EQ(errorFor(dir, "exact.pcd", h + std::string(12000, '\0')), "");
}

// A header may announce anything: nothing is allocated beyond what the file's bytes can hold, so these
// fail at once instead of allocating gigabytes (they did with PCL).
TEST(PcdFormat, HugeCountsInTheHeaderFailFastWithoutAllocating) {
  TempDir dir;
  const auto start = std::chrono::steady_clock::now();
  for (const char* data : {"ascii", "binary"}) {
    expectError(errorFor(dir, "w.pcd", header("x y z", "4 4 4", "F F F", "1 1 1", "4000000000", data) + "1 2 3\n"),
                "truncated");
    expectError(errorFor(dir, "h.pcd", header("x y z", "4 4 4", "F F F", "1 1 1", "4000000000", data, "4000000000")),
                "truncated");
    expectError(errorFor(dir, "c.pcd", header("x y z", "4 4 4", "F F F", "1 1 1000000", "1", data) + "1 2 3\n"),
                "truncated");
  }
  expectError(errorFor(dir, "n.pcd", header("x y z", "4 4 4", "F F F", "1 1 4000000000", "1", "binary")), "COUNT 4000000000");
  expectError(errorFor(dir, "o.pcd", header("x y z", "4 4 4", "F F F", "1 1 1", "18446744073709551615", "binary", "2")),
              "overflows");
  expectError(errorFor(dir, "p.pcd", kXyz.substr(0, kXyz.size() - 11) + "POINTS 7\nDATA ascii\n"), "POINTS 7 is not WIDTH x HEIGHT = 2");
  // binary_compressed: a raw size the compressed bytes cannot expand to.
  std::string sizes(8, '\0');
  const std::uint32_t compressed = 4, raw = 120000000;
  std::memcpy(&sizes[0], &compressed, 4);
  std::memcpy(&sizes[4], &raw, 4);
  expectError(errorFor(dir, "z.pcd", header("x y z", "4 4 4", "F F F", "1 1 1", "10000000", "binary_compressed") + sizes + "abcd"),
              "cannot expand");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
}

TEST(PcdFormat, BadHeadersNameTheProblem) {
  TempDir dir;
  expectError(errorFor(dir, "empty.pcd", ""), "is empty");
  expectError(errorFor(dir, "text.pcd", "hello world\n"), "line 1: 'hello' is not a PCD header entry");
  expectError(errorFor(dir, "nodata.pcd", "VERSION 0.7\nFIELDS x\n"), "has no DATA line");
  expectError(errorFor(dir, "type.pcd", header("x y z", "4 4 2", "F F F", "1 1 1", "1", "binary")), "TYPE F with SIZE 2");
  expectError(errorFor(dir, "mismatch.pcd", header("x y z", "4 4", "F F F", "1 1 1", "1", "binary")), "different numbers");
  expectError(errorFor(dir, "width.pcd", header("x y z", "4 4 4", "F F F", "1 1 1", "-3", "binary")),
              "WIDTH value '-3' is not a non-negative integer");
  expectError(errorFor(dir, "enc.pcd", header("x y z", "4 4 4", "F F F", "1 1 1", "1", "zip")), "DATA must be");
  expectError(errorFor(dir, "noxyz.pcd", header("a", "4", "F", "1", "1", "ascii") + "1\n"), "has no x, y and z fields");
}

TEST(PcdFormat, CorruptLzfIsAnErrorNeverAnOutOfBoundsCopy) {
  std::uint8_t out[16];
  const std::uint8_t literal[] = {3, 1, 2, 3, 4};
  EXPECT_TRUE(lzfDecompress(literal, sizeof(literal), out, 4));
  EXPECT_FALSE(lzfDecompress(literal, sizeof(literal), out, 3));             // more output than room
  EXPECT_FALSE(lzfDecompress(literal, 3, out, 4));                             // literal run cut short
  const std::uint8_t before_start[] = {0, 7, (1 << 5) | 0, 5};                // distance 6 after 1 byte
  EXPECT_FALSE(lzfDecompress(before_start, sizeof(before_start), out, 4));
  const std::uint8_t run[] = {0, 9, (2 << 5) | 0, 0};                          // 1 literal + copy 4 at distance 1
  ASSERT_TRUE(lzfDecompress(run, sizeof(run), out, 5));
  for (int i = 0; i < 5; ++i) EXPECT_EQ(out[i], 9);
  const std::uint8_t cut_reference[] = {0, 9, (2 << 5) | 0};
  EXPECT_FALSE(lzfDecompress(cut_reference, sizeof(cut_reference), out, 5));
}

// Stamps too large for utime (int64 microseconds) are not stamps: no overflow, no exception.
TEST(PcdFormat, AbsurdStampsAreIgnored) {
  std::int64_t utime = 0;
  EXPECT_FALSE(pcdStampFromFileName("d/9999999999999999999.pcd", utime));  // 19 digits above INT64_MAX
  EXPECT_FALSE(pcdStampFromFileName("d/1.0e300.pcd", utime));
  EXPECT_TRUE(pcdStampFromFileName("d/1611234567.123456.pcd", utime));
  EXPECT_EQ(utime, 1611234567123456);
  TempDir dir;
  dir.write("t.pcd", header("x y z time", "4 4 4 8", "F F F F", "1 1 1 1", "2", "ascii") + "1 2 3 1e300\n4 5 6 2e300\n");
  const LidarScan scan = readPcdScan(dir.file("t.pcd"), PcdFolderConfig{}, 7, 0);
  EXPECT_FALSE(scan.has_time);
  EXPECT_EQ(scan.utime, 7);
}

TEST(PcdFormat, ReadsCountFieldsAndAsciiNan) {
  TempDir dir;
  dir.write("n.pcd", header("x y z normal", "8 8 8 4", "F F F F", "1 1 1 3", "2", "ascii") + "1 2 3 0 0 1\nnan nan nan 0 1 0\n");
  const PcdCloud cloud = readPcdFile(dir.file("n.pcd"));
  ASSERT_EQ(cloud.points, 2u);
  EXPECT_EQ(cloud.point_step, 36u);
  EXPECT_DOUBLE_EQ(cloud.field("z")->read(cloud.data.data()), 3.0);
  EXPECT_TRUE(std::isnan(cloud.field("x")->read(cloud.data.data() + cloud.point_step)));
}

// writePcd's header is PCL's, byte for byte: maps stay readable by every PCD tool.
TEST(PcdFormat, BinaryHeaderMatchesPcl) {
  pcl::PCLPointCloud2 cloud;
  std::vector<PcdField> fields;
  std::uint32_t offset = 0;
  for (const auto& [name, type, size] : {std::tuple<const char*, char, int>{"x", 'F', 4}, {"y", 'F', 4}, {"ring", 'U', 2}, {"time", 'F', 4}}) {
    pcl::PCLPointField pf;
    pf.name = name;
    pf.offset = offset;
    pf.datatype = type == 'U' ? pcl::PCLPointField::UINT16 : pcl::PCLPointField::FLOAT32;
    pf.count = 1;
    cloud.fields.push_back(pf);
    offset += static_cast<std::uint32_t>(size);
    PcdField f;
    f.name = name;
    f.type = type;
    f.size = static_cast<std::uint32_t>(size);
    fields.push_back(f);
  }
  cloud.point_step = offset;
  cloud.width = 7;
  cloud.height = 1;
  pcl::PCDWriter writer;
  EXPECT_EQ(pcdBinaryHeader(fields, 7),
            writer.generateHeaderBinary(cloud, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity()) + "DATA binary\n");
}

}  // namespace
}  // namespace adit::io
