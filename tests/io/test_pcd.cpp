// PCD fixtures are written here with PCL itself (ascii, binary, binary_compressed, custom field types),
// then read back through adit::io.
#include <gtest/gtest.h>

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <cmath>
#include <cstring>
#include <random>

#include "io/pcd.hpp"
#include "io/rings.hpp"
#include "temp_dir.hpp"

namespace adit::io {
namespace {

using test::TempDir;
constexpr double kDeg = M_PI / 180.0;

enum class Format { kAscii, kBinary, kCompressed };

// A field layout and per-point values (as double) to write.
struct FixtureField {
  std::string name;
  std::uint8_t datatype;
  std::function<double(int)> value;
};

std::uint32_t sizeOf(std::uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::UINT8: return 1;
    case pcl::PCLPointField::UINT16: return 2;
    case pcl::PCLPointField::UINT32:
    case pcl::PCLPointField::FLOAT32: return 4;
    default: return 8;  // FLOAT64
  }
}

void store(std::uint8_t* out, std::uint8_t datatype, double v) {
  switch (datatype) {
    case pcl::PCLPointField::UINT8: { auto x = static_cast<std::uint8_t>(v); std::memcpy(out, &x, 1); break; }
    case pcl::PCLPointField::UINT16: { auto x = static_cast<std::uint16_t>(v); std::memcpy(out, &x, 2); break; }
    case pcl::PCLPointField::UINT32: { auto x = static_cast<std::uint32_t>(v); std::memcpy(out, &x, 4); break; }
    case pcl::PCLPointField::FLOAT32: { auto x = static_cast<float>(v); std::memcpy(out, &x, 4); break; }
    default: std::memcpy(out, &v, 8);
  }
}

void writeFixture(const std::string& path, int n, const std::vector<FixtureField>& fields, Format format) {
  pcl::PCLPointCloud2 cloud;
  std::uint32_t offset = 0;
  for (const auto& f : fields) {
    pcl::PCLPointField pf;
    pf.name = f.name;
    pf.offset = offset;
    pf.datatype = f.datatype;
    pf.count = 1;
    cloud.fields.push_back(pf);
    offset += sizeOf(f.datatype);
  }
  cloud.point_step = offset;
  cloud.width = static_cast<std::uint32_t>(n);
  cloud.height = 1;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.data.resize(cloud.row_step);
  for (int i = 0; i < n; ++i)
    for (size_t k = 0; k < fields.size(); ++k)
      store(cloud.data.data() + i * cloud.point_step + cloud.fields[k].offset, fields[k].datatype, fields[k].value(i));
  pcl::PCDWriter writer;
  int status = -1;
  if (format == Format::kAscii) status = writer.writeASCII(path, cloud, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(), 9);
  if (format == Format::kBinary) status = writer.writeBinary(path, cloud);
  if (format == Format::kCompressed) status = writer.writeBinaryCompressed(path, cloud);
  ASSERT_EQ(status, 0) << path;
}

// A VLP-16-like sweep: point i is on beam i % 16, azimuth sweeping once around, time 0..0.1 s.
constexpr int kN = 1600;
int beamOf(int i) { return i % 16; }
double azimuthOf(int i) { return -M_PI + 2.0 * M_PI * (i + 0.5) / kN; }
double timeOf(int i) { return 0.1 * i / (kN - 1); }
double coord(int i, int axis) {
  const double el = vlp16Elevations()[static_cast<size_t>(beamOf(i))], r = 5.0 + (i % 7);
  const double xyz[3] = {r * std::cos(el) * std::cos(azimuthOf(i)), r * std::cos(el) * std::sin(azimuthOf(i)), r * std::sin(el)};
  return xyz[axis];
}
std::vector<FixtureField> xyzFields() {
  return {{"x", pcl::PCLPointField::FLOAT32, [](int i) { return coord(i, 0); }},
          {"y", pcl::PCLPointField::FLOAT32, [](int i) { return coord(i, 1); }},
          {"z", pcl::PCLPointField::FLOAT32, [](int i) { return coord(i, 2); }}};
}

void expectGeometry(const LidarScan& scan) {
  ASSERT_EQ(scan.points.size(), static_cast<size_t>(kN));
  for (int i = 0; i < kN; i += 97) {
    EXPECT_NEAR(scan.points[i].p.x(), coord(i, 0), 1e-5);
    EXPECT_NEAR(scan.points[i].p.z(), coord(i, 2), 1e-5);
  }
}

class PcdFormats : public ::testing::TestWithParam<Format> {};

TEST_P(PcdFormats, VelodyneStyleRingAndFloatTime) {
  TempDir dir;
  auto fields = xyzFields();
  fields.push_back({"intensity", pcl::PCLPointField::FLOAT32, [](int i) { return i % 100; }});
  fields.push_back({"ring", pcl::PCLPointField::UINT16, [](int i) { return beamOf(i); }});
  fields.push_back({"time", pcl::PCLPointField::FLOAT32, timeOf});
  writeFixture(dir.file("a.pcd"), kN, fields, GetParam());
  PcdScanReport report;
  const LidarScan scan = readPcdScan(dir.file("a.pcd"), PcdFolderConfig{}, 42, 3, &report);
  expectGeometry(scan);
  EXPECT_TRUE(report.ring_field);
  EXPECT_EQ(report.time_field, "time");
  EXPECT_TRUE(scan.has_ring);
  EXPECT_TRUE(scan.has_time);
  EXPECT_EQ(scan.num_beams, 16);
  EXPECT_EQ(scan.utime, 42);
  EXPECT_EQ(scan.seq, 3);
  EXPECT_EQ(scan.points[5].ring, 5);
  EXPECT_FLOAT_EQ(scan.points[77].intensity, 77.0f);
  EXPECT_NEAR(scan.points.front().dt, -0.1, 1e-6);
  EXPECT_NEAR(scan.points[kN / 2].dt, timeOf(kN / 2) - 0.1, 1e-6);
  EXPECT_EQ(scan.points.back().dt, 0.0f);
}

TEST_P(PcdFormats, NoRingNoTimeGetsRingsFromTheBeamTable) {
  TempDir dir;
  writeFixture(dir.file("b.pcd"), kN, xyzFields(), GetParam());
  PcdScanReport report;
  const LidarScan scan = readPcdScan(dir.file("b.pcd"), PcdFolderConfig{}, 0, 0, &report);
  expectGeometry(scan);
  EXPECT_FALSE(report.ring_field);
  EXPECT_TRUE(report.time_field.empty());
  EXPECT_TRUE(scan.has_ring);
  EXPECT_FALSE(scan.has_time);
  EXPECT_EQ(scan.num_beams, 16);
  EXPECT_EQ(report.far_from_beam, 0);
  for (int i = 0; i < kN; ++i) ASSERT_EQ(scan.points[i].ring, beamOf(i)) << i;
  for (const LidarPoint& pt : scan.points) ASSERT_EQ(pt.intensity, 0.0f);
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PcdFormats,
                         ::testing::Values(Format::kAscii, Format::kBinary, Format::kCompressed));

TEST(Pcd, OusterStyleIntegerNanosecondsAndUint8Ring) {
  TempDir dir;
  auto fields = xyzFields();
  fields.push_back({"t", pcl::PCLPointField::UINT32, [](int i) { return std::round(timeOf(i) * 1e9); }});
  fields.push_back({"ring", pcl::PCLPointField::UINT8, [](int i) { return beamOf(i); }});
  writeFixture(dir.file("c.pcd"), kN, fields, Format::kBinary);
  PcdScanReport report;
  const LidarScan scan = readPcdScan(dir.file("c.pcd"), PcdFolderConfig{}, 0, 0, &report);
  EXPECT_EQ(report.time_field, "t");
  EXPECT_TRUE(scan.has_time);
  EXPECT_NEAR(scan.points.front().dt, -0.1, 1e-7);
  EXPECT_NEAR(scan.points[400].dt, timeOf(400) - 0.1, 1e-7);
  EXPECT_EQ(scan.points[15].ring, 15);
}

TEST(Pcd, AbsoluteDoubleTimestampsSetTheUtime) {
  TempDir dir;
  auto fields = xyzFields();
  fields.push_back({"timestamp", pcl::PCLPointField::FLOAT64, [](int i) { return 1611234567.5 + timeOf(i); }});
  writeFixture(dir.file("d.pcd"), kN, fields, Format::kBinary);  // PCL's ascii writer keeps < 17 digits
  PcdScanReport report;
  const LidarScan scan = readPcdScan(dir.file("d.pcd"), PcdFolderConfig{}, 0, 0, &report);
  EXPECT_TRUE(report.absolute_times);
  EXPECT_EQ(scan.utime, 1611234567600000);
  EXPECT_NEAR(scan.points.front().dt, -0.1, 1e-6);
}

TEST(Pcd, ConstantTimeFieldCarriesNoTiming) {
  TempDir dir;
  auto fields = xyzFields();
  fields.push_back({"time", pcl::PCLPointField::FLOAT32, [](int) { return 0.0; }});
  writeFixture(dir.file("e.pcd"), kN, fields, Format::kBinary);
  EXPECT_FALSE(readPcdScan(dir.file("e.pcd"), PcdFolderConfig{}, 0, 0).has_time);
}

TEST(Pcd, UniformFanForAnUnknownSensor) {
  TempDir dir;
  writeFixture(dir.file("f.pcd"), kN, xyzFields(), Format::kBinary);
  PcdFolderConfig config;
  config.sensor = "mystery";
  EXPECT_FALSE(readPcdScan(dir.file("f.pcd"), config, 0, 0).has_ring);
  config.num_beams = 16;
  const LidarScan scan = readPcdScan(dir.file("f.pcd"), config, 0, 0);
  EXPECT_TRUE(scan.has_ring);
  for (int i = 0; i < kN; ++i) ASSERT_EQ(scan.points[i].ring, beamOf(i)) << i;
}

TEST(Pcd, WritePcdRoundTripsEveryField) {
  TempDir dir;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-50.0f, 50.0f);
  std::vector<LidarPoint> points(2000);
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].p = Eigen::Vector3f(u(rng), u(rng), u(rng) * 0.1f);
    points[i].intensity = static_cast<float>(i % 256);
    points[i].ring = static_cast<std::uint16_t>(i % 16);
    points[i].dt = -0.1f + 0.1f * static_cast<float>(i) / 1999.0f;
  }
  points[10].p.x() = NAN;
  writePcd(dir.file("map.pcd"), points, {true, true});
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"map.pcd"});  // no temp file left
  PcdScanReport report;
  const LidarScan scan = readPcdScan(dir.file("map.pcd"), PcdFolderConfig{}, 0, 0, &report);
  ASSERT_EQ(scan.points.size(), points.size());
  EXPECT_EQ(report.nan_points, 1);
  EXPECT_TRUE(scan.has_ring);
  EXPECT_TRUE(scan.has_time);
  for (size_t i = 0; i < points.size(); ++i) {
    if (i == 10) continue;
    ASSERT_EQ(scan.points[i].p, points[i].p) << i;  // binary: bit-exact
    ASSERT_EQ(scan.points[i].intensity, points[i].intensity);
    ASSERT_EQ(scan.points[i].ring, points[i].ring);
    ASSERT_NEAR(scan.points[i].dt, points[i].dt, 1e-7);  // re-based on the largest time (0)
  }
  EXPECT_TRUE(std::isnan(scan.points[10].p.x()));

  writePcd(dir.file("plain.pcd"), points);
  const LidarScan plain = readPcdScan(dir.file("plain.pcd"), PcdFolderConfig{}, 0, 0, &report);
  EXPECT_FALSE(report.ring_field);
  EXPECT_TRUE(report.time_field.empty());
  EXPECT_EQ(plain.points[7].p, points[7].p);
}

TEST(Pcd, EmptyCloudRoundTrips) {
  TempDir dir;
  writePcd(dir.file("empty.pcd"), {});
  EXPECT_TRUE(readPcdScan(dir.file("empty.pcd"), PcdFolderConfig{}, 0, 0).points.empty());
}

TEST(Pcd, FileNameStamps) {
  std::int64_t utime = 0;
  EXPECT_TRUE(pcdStampFromFileName("/x/1611234567.250000.pcd", utime));
  EXPECT_EQ(utime, 1611234567250000);
  EXPECT_TRUE(pcdStampFromFileName("1611234567250000999.pcd", utime));
  EXPECT_EQ(utime, 1611234567250001);
  EXPECT_FALSE(pcdStampFromFileName("000042.pcd", utime));
  EXPECT_FALSE(pcdStampFromFileName("scan_1.5.pcd", utime));
}

TEST(Pcd, FolderUsesNameStampsOrIndexTimesSortedByName) {
  TempDir dir;
  for (const char* name : {"100.200000.pcd", "100.100000.pcd", "100.300000.pcd"})
    writeFixture(dir.file(name), 16, xyzFields(), Format::kBinary);
  const PcdFolder stamped(dir.path(), PcdFolderConfig{});
  ASSERT_EQ(stamped.size(), 3u);
  EXPECT_TRUE(stamped.namesAreTimestamps());
  EXPECT_EQ(stamped.scan(0).utime, 100100000);
  EXPECT_EQ(stamped.scan(2).utime, 100300000);
  EXPECT_EQ(stamped.scan(2).seq, 2);

  PcdFolderConfig start;
  start.stamp_is_sweep_start = true;
  EXPECT_EQ(PcdFolder(dir.path(), start).scan(0).utime, 100200000);  // + sweep_duration without times

  writeFixture(dir.file("000001.pcd"), 16, xyzFields(), Format::kBinary);
  PcdFolderConfig indexed;
  indexed.first_utime = 5000000;
  const PcdFolder numbered(dir.path(), indexed);
  ASSERT_EQ(numbered.size(), 4u);
  EXPECT_FALSE(numbered.namesAreTimestamps());
  EXPECT_EQ(numbered.scan(0).utime, 5000000);
  EXPECT_EQ(numbered.scan(3).utime, 5300000);
}

TEST(Pcd, CorruptTruncatedAndMissingFilesAreErrorsNamingTheFile) {
  TempDir dir;
  dir.write("garbage.pcd", "this is not a point cloud\n");
  writeFixture(dir.file("whole.pcd"), kN, xyzFields(), Format::kBinary);
  const std::string bytes = test::readAll(dir.file("whole.pcd"));
  dir.write("cut.pcd", bytes.substr(0, bytes.size() / 2));  // PCL pads binary files: cut deep
  writeFixture(dir.file("nox.pcd"), 4, {{"a", pcl::PCLPointField::FLOAT32, [](int) { return 1.0; }}}, Format::kAscii);
  for (const char* name : {"garbage.pcd", "cut.pcd", "nox.pcd", "missing.pcd"}) {
    try {
      readPcdScan(dir.file(name), PcdFolderConfig{}, 0, 0);
      ADD_FAILURE() << "expected ReadError for " << name;
    } catch (const ReadError& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(PcdFolder("/nonexistent/folder", PcdFolderConfig{}), ReadError);
}

// Truncating a file anywhere, or overwriting bytes of its header, gives a ReadError or a valid scan:
// never a crash (PCL alone segfaults on some of these).
TEST(Pcd, DamagedFilesNeverCrash) {
  TempDir dir;
  std::mt19937 rng(11);
  auto fields = xyzFields();
  fields.push_back({"ring", pcl::PCLPointField::UINT16, [](int i) { return beamOf(i); }});
  for (Format format : {Format::kAscii, Format::kBinary, Format::kCompressed}) {
    writeFixture(dir.file("src.pcd"), kN, fields, format);
    const std::string bytes = test::readAll(dir.file("src.pcd"));
    for (int trial = 0; trial < 40; ++trial) {
      std::string damaged = bytes;
      if (trial < 20) {
        damaged.resize(bytes.size() * static_cast<size_t>(trial) / 20);
      } else {
        std::uniform_int_distribution<size_t> at(0, 200);
        for (int k = 0; k < 3; ++k) damaged[at(rng)] = static_cast<char>(rng() % 256);
      }
      dir.write("damaged.pcd", damaged);
      try {
        const LidarScan scan = readPcdScan(dir.file("damaged.pcd"), PcdFolderConfig{}, 0, 0);
        EXPECT_LE(scan.points.size(), static_cast<size_t>(kN) * 2);
      } catch (const ReadError& e) {
        EXPECT_NE(std::string(e.what()).find("damaged.pcd"), std::string::npos) << e.what();
      }
    }
  }
}

TEST(Pcd, ConfigKeys) {
  Config c;
  c.set("pcd.sensor", "rs16");
  c.set("pcd.stamp_is_sweep_start", "true");
  const PcdFolderConfig config = pcdFolderConfigFrom(c);
  EXPECT_EQ(config.sensor, "rs16");
  EXPECT_TRUE(config.stamp_is_sweep_start);
  EXPECT_DOUBLE_EQ(config.sweep_duration, 0.1);
}

}  // namespace
}  // namespace adit::io
