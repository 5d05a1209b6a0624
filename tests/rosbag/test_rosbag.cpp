// The bag reader and the PointCloud2 / Imu decoders on bags the test writes itself (bag_writer.hpp):
// every compression, two driver layouts, IMU; a corrupted chunk; truncated, empty and random files.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <random>

#include "bag_writer.hpp"
#include "clouds.hpp"
#include "io/ros_messages.hpp"
#include "io/rosbag.hpp"
#include "../io/temp_dir.hpp"

namespace adit::test {
namespace {

constexpr std::uint32_t kSec = 1600000000;

ImuSample imuAt(int k) {
  ImuSample s;
  s.gyro = Eigen::Vector3d(0.01 * k, -0.02, 0.3);
  s.accel = Eigen::Vector3d(0.1, 0.2 * k, 9.81);
  if (k % 2) s.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d::UnitZ()));
  return s;
}

std::int64_t nsOf(std::uint32_t sec, std::uint32_t nsec) { return std::int64_t{sec} * 1000000000 + nsec; }

// Four sweeps (alternating Velodyne / Ouster layouts) and ten IMU samples between each, two sweeps per chunk.
struct TestBag {
  std::string bytes;
  std::vector<TestCloud> clouds;
  std::vector<ImuSample> imu;
  std::vector<std::int64_t> imu_utime;
  std::vector<std::pair<std::size_t, std::size_t>> chunks;
  std::vector<std::uint64_t> chunk_records;  // file offsets of the chunk records
};

TestBag makeBag(const std::string& compression) {
  TestBag b;
  BagWriter w(compression);
  w.addConnection(0, "/points", "sensor_msgs/PointCloud2");
  w.addConnection(1, "/imu", "sensor_msgs/Imu");
  for (int k = 0; k < 4; ++k) {
    const std::uint32_t nsec = 100000000u * static_cast<std::uint32_t>(k) + 123456;
    b.clouds.push_back(k % 2 ? ousterCloud(kSec, nsec, 64, k, k == 3 ? 12 : 0) : velodyneCloud(kSec, nsec, 90, k));
    w.addMessage(0, nsOf(kSec, nsec) + 5000000, b.clouds.back().message);
    for (int i = 0; i < 10; ++i) {
      const std::uint32_t imu_nsec = nsec + 10000000u * static_cast<std::uint32_t>(i);
      b.imu.push_back(imuAt(k * 10 + i));
      b.imu_utime.push_back(io::RosStamp{kSec, imu_nsec}.utime());
      w.addMessage(1, nsOf(kSec, imu_nsec) + 1000000, imuMessage(kSec, imu_nsec, b.imu.back()));
    }
    if (k % 2) b.chunks.push_back(w.endChunk());
  }
  b.bytes = w.finish();
  b.chunk_records = w.chunkPositions();
  return b;
}

void expectCloud(const LidarScan& scan, const TestCloud& want) {
  EXPECT_EQ(scan.utime, want.expected_utime);
  EXPECT_TRUE(scan.has_ring);
  EXPECT_TRUE(scan.has_time);
  EXPECT_EQ(scan.num_beams, 16);
  ASSERT_EQ(scan.points.size(), want.expected.size());
  for (std::size_t i = 0; i < want.expected.size(); ++i) {
    const LidarPoint &got = scan.points[i], &exp = want.expected[i];
    ASSERT_LE((got.p - exp.p).cast<double>().norm(), 1e-6) << i;
    ASSERT_EQ(got.ring, exp.ring) << i;
    ASSERT_EQ(got.dt, exp.dt) << i;
    ASSERT_EQ(got.intensity, exp.intensity) << i;
  }
}

// Reads every message and decodes it by type; counts what it saw.
struct ReadBack {
  std::vector<LidarScan> scans;
  std::vector<ImuSample> imu;
  io::BagReadStats stats;
  std::map<std::string, int> per_topic;
};

ReadBack readBag(const std::string& path) {
  ReadBack r;
  io::BagReader reader(path);
  io::BagMessage m;
  io::PcdFolderConfig config;
  while (reader.next(m)) {
    const io::BagConnection& c = reader.connections().at(m.conn);
    r.per_topic[c.topic] += 1;
    if (c.type == "sensor_msgs/PointCloud2")
      r.scans.push_back(io::decodePointCloud2(m.data.data(), m.data.size(), config, m.time_ns / 1000));
    else if (c.type == "sensor_msgs/Imu")
      r.imu.push_back(io::decodeImu(m.data.data(), m.data.size(), m.time_ns / 1000));
  }
  r.stats = reader.stats();
  return r;
}

class RosbagCompression : public ::testing::TestWithParam<std::string> {};

TEST_P(RosbagCompression, ReadsEveryMessageExactly) {
  io::test::TempDir dir;
  const TestBag bag = makeBag(GetParam());
  dir.write("run.bag", bag.bytes);
  const ReadBack r = readBag(dir.file("run.bag"));
  EXPECT_EQ(r.stats.chunks, 2);
  EXPECT_EQ(r.stats.chunks_lost, 0);
  EXPECT_FALSE(r.stats.truncated) << r.stats.last_error;
  EXPECT_EQ(r.per_topic.at("/points"), 4);
  EXPECT_EQ(r.per_topic.at("/imu"), 40);
  ASSERT_EQ(r.scans.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) expectCloud(r.scans[k], bag.clouds[k]);
  ASSERT_EQ(r.imu.size(), bag.imu.size());
  for (std::size_t i = 0; i < bag.imu.size(); ++i) {
    EXPECT_EQ(r.imu[i].utime, bag.imu_utime[i]);
    EXPECT_EQ(r.imu[i].gyro, bag.imu[i].gyro);
    EXPECT_EQ(r.imu[i].accel, bag.imu[i].accel);
    ASSERT_EQ(r.imu[i].orientation.has_value(), bag.imu[i].orientation.has_value());
    if (bag.imu[i].orientation) {
      EXPECT_LT(r.imu[i].orientation->angularDistance(*bag.imu[i].orientation), 1e-12);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllCompressions, RosbagCompression, ::testing::Values("none", "bz2", "lz4"));

TEST(Rosbag, CorruptChunkLosesOnlyThatChunk) {
  for (const std::string compression : {"none", "bz2", "lz4"}) {
    io::test::TempDir dir;
    TestBag bag = makeBag(compression);
    const auto [begin, end] = bag.chunks[0];
    if (compression == "none") {  // an uncompressed chunk cannot fail to decompress: break a record length inside
      bag.bytes[begin + 1] = '\x7f';
    } else {
      for (std::size_t i = begin + (end - begin) / 3; i < begin + (end - begin) / 2; ++i) bag.bytes[i] = static_cast<char>(bag.bytes[i] ^ 0x5a);
    }
    dir.write("run.bag", bag.bytes);
    const ReadBack r = readBag(dir.file("run.bag"));
    EXPECT_EQ(r.stats.chunks, 2) << compression;
    EXPECT_EQ(r.stats.chunks_lost, 1) << compression;
    EXPECT_NE(r.stats.last_error.find("chunk 1"), std::string::npos) << r.stats.last_error;
    ASSERT_EQ(r.scans.size(), 2u) << compression;  // the second chunk's sweeps, intact
    expectCloud(r.scans[0], bag.clouds[2]);
    expectCloud(r.scans[1], bag.clouds[3]);
    EXPECT_EQ(r.imu.size(), 20u);
  }
}

TEST(Rosbag, BrokenChunkHeaderIsSkippedThroughTheIndex) {
  io::test::TempDir dir;
  TestBag bag = makeBag("bz2");
  const std::uint32_t huge = 0xFFFFFFF0u;  // the first chunk's header length: the file's framing breaks there
  std::memcpy(&bag.bytes[bag.chunk_records[0]], &huge, 4);
  dir.write("run.bag", bag.bytes);
  const ReadBack r = readBag(dir.file("run.bag"));
  EXPECT_EQ(r.stats.resyncs, 1);
  EXPECT_EQ(r.stats.chunks_lost, 1);
  EXPECT_FALSE(r.stats.truncated);
  EXPECT_NE(r.stats.last_error.find("resumed at the next indexed chunk"), std::string::npos) << r.stats.last_error;
  ASSERT_EQ(r.scans.size(), 2u);
  expectCloud(r.scans[0], bag.clouds[2]);
  expectCloud(r.scans[1], bag.clouds[3]);

  // Without an index entry beyond the break (the second chunk's header), the reading ends there.
  TestBag last = makeBag("lz4");
  std::memcpy(&last.bytes[last.chunk_records[1]], &huge, 4);
  dir.write("last.bag", last.bytes);
  const ReadBack l = readBag(dir.file("last.bag"));
  EXPECT_TRUE(l.stats.truncated);
  EXPECT_EQ(l.scans.size(), 2u);
}

TEST(Rosbag, CorruptIndexStillReadsTheChunks) {
  io::test::TempDir dir;
  TestBag bag = makeBag("lz4");
  const std::size_t index = bag.chunks[1].second;  // the trailing connections and chunk infos start here
  for (std::size_t i = index; i < bag.bytes.size(); i += 3) bag.bytes[i] = static_cast<char>(0xA5);
  dir.write("run.bag", bag.bytes);
  const ReadBack r = readBag(dir.file("run.bag"));
  EXPECT_EQ(r.stats.chunks_lost, 0);
  EXPECT_EQ(r.scans.size(), 4u);
  EXPECT_EQ(r.imu.size(), 40u);
}

TEST(Rosbag, UnknownCompressionLosesTheChunk) {
  io::test::TempDir dir;
  BagWriter w("zstd");
  w.addConnection(0, "/imu", "sensor_msgs/Imu");
  w.addMessage(0, nsOf(kSec, 0), imuMessage(kSec, 0, imuAt(0)));
  dir.write("run.bag", w.finish());
  const ReadBack r = readBag(dir.file("run.bag"));
  EXPECT_EQ(r.stats.chunks_lost, 1);
  EXPECT_NE(r.stats.last_error.find("unknown compression 'zstd'"), std::string::npos) << r.stats.last_error;
}

TEST(Rosbag, TruncatedBagKeepsWhatCameBefore) {
  io::test::TempDir dir;
  const TestBag bag = makeBag("lz4");
  dir.write("run.bag", bag.bytes.substr(0, bag.chunks[1].first + 100));  // cut inside the second chunk
  const ReadBack r = readBag(dir.file("run.bag"));
  EXPECT_TRUE(r.stats.truncated);
  EXPECT_NE(r.stats.last_error.find("runs past the end"), std::string::npos) << r.stats.last_error;
  EXPECT_EQ(r.scans.size(), 2u);
  EXPECT_EQ(r.imu.size(), 20u);
}

TEST(Rosbag, NotABagIsOneLineError) {
  io::test::TempDir dir;
  std::mt19937 rng(7);
  std::string random(5000, '\0');
  for (char& c : random) c = static_cast<char>(rng());
  const TestBag bag = makeBag("none");
  const std::pair<std::string, std::string> cases[] = {
      {"empty", ""}, {"random", random}, {"version only", "#ROSBAG V2.0\n"},
      {"cut header", bag.bytes.substr(0, 200)}, {"v1.2", "#ROSBAG V1.2\n" + random}};
  for (const auto& [name, bytes] : cases) {
    dir.write("bad.bag", bytes);
    try {
      io::BagReader reader(dir.file("bad.bag"));
      ADD_FAILURE() << name << " opened";
    } catch (const io::ReadError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << name;
      EXPECT_NE(what.find("bad.bag"), std::string::npos) << name << ": " << what;
    }
  }
}

TEST(Rosbag, RandomBytesAfterTheHeaderNeverCrash) {
  io::test::TempDir dir;
  const TestBag bag = makeBag("bz2");
  std::mt19937 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    std::string bytes = bag.bytes;
    for (int k = 0; k < 8; ++k) bytes[4200 + rng() % (bytes.size() - 4200)] = static_cast<char>(rng());
    bytes.resize(4200 + rng() % (bytes.size() - 4200));
    dir.write("bad.bag", bytes);
    io::BagReader reader(dir.file("bad.bag"));
    io::BagMessage m;
    int n = 0;
    while (reader.next(m)) {
      ++n;
      try {
        io::decodePointCloud2(m.data.data(), m.data.size(), io::PcdFolderConfig{}, 0);
      } catch (const io::ReadError&) {
      }
    }
    EXPECT_LE(n, 44);
  }
}

TEST(RosMessages, CloudWithoutRingGetsRingsByElevation) {
  const TestCloud velodyne = velodyneCloud(kSec, 0, 36, 3);
  // The same points with only x y z float64 and no time: rebuild a message from the expected points.
  Bytes data;
  for (const LidarPoint& p : velodyne.expected)
    for (int a = 0; a < 3; ++a) put<double>(data, p.p[a]);
  const Bytes msg = pointCloud2(kSec, 500000000, {{"x", 0, 8}, {"y", 8, 8}, {"z", 16, 8}}, 24, data);
  io::PcdFolderConfig config;
  config.sensor = "vlp16";
  const LidarScan scan = io::decodePointCloud2(msg.data(), msg.size(), config, 0);
  EXPECT_EQ(scan.utime, std::int64_t{kSec} * 1000000 + 500000);  // no times: the stamp
  EXPECT_FALSE(scan.has_time);
  EXPECT_TRUE(scan.has_ring);
  ASSERT_EQ(scan.points.size(), velodyne.expected.size());
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    EXPECT_EQ(scan.points[i].ring, velodyne.expected[i].ring);
    EXPECT_LE((scan.points[i].p - velodyne.expected[i].p).norm(), 1e-6);
  }
}

TEST(RosMessages, AbsoluteTimesGiveTheLastFiring) {
  // Hesai / RoboSense: `timestamp` float64 epoch seconds per point.
  Bytes data;
  const double t0 = 1600000000.25;
  for (int i = 0; i < 100; ++i) {
    put<float>(data, 10.0f + 0.01f * i);
    put<float>(data, 1.0f);
    put<float>(data, 0.5f);
    put<double>(data, t0 + 0.001 * i);
  }
  const Bytes msg = pointCloud2(1600000000, 250000000, {{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}, {"timestamp", 12, 8}}, 20, data);
  const LidarScan scan = io::decodePointCloud2(msg.data(), msg.size(), io::PcdFolderConfig{}, 0);
  EXPECT_TRUE(scan.has_time);
  EXPECT_EQ(scan.utime, toUtime(t0 + 0.099));
  EXPECT_NEAR(scan.points.front().dt, -0.099, 1e-6);
  EXPECT_EQ(scan.points.back().dt, 0.0f);
}

TEST(RosMessages, MalformedCloudsAreDecodeErrors) {
  const TestCloud good = velodyneCloud(kSec, 0, 8, 0);
  const io::PcdFolderConfig config;
  for (std::size_t cut : {std::size_t{0}, std::size_t{10}, good.message.size() / 2, good.message.size() - 2})
    EXPECT_THROW(io::decodePointCloud2(good.message.data(), cut, config, 0), io::DecodeError) << cut;
  Bytes data(40, 0);
  const Bytes outside = pointCloud2(kSec, 0, {{"x", 0, 7}, {"y", 4, 7}, {"z", 18, 7}}, 20, data);
  EXPECT_THROW(io::decodePointCloud2(outside.data(), outside.size(), config, 0), io::DecodeError);
  const Bytes bad_type = pointCloud2(kSec, 0, {{"x", 0, 9}, {"y", 4, 7}, {"z", 8, 7}}, 20, data);
  EXPECT_THROW(io::decodePointCloud2(bad_type.data(), bad_type.size(), config, 0), io::DecodeError);
  const Bytes no_z = pointCloud2(kSec, 0, {{"x", 0, 7}, {"y", 4, 7}}, 20, data);
  EXPECT_THROW(io::decodePointCloud2(no_z.data(), no_z.size(), config, 0), io::ReadError);
  Bytes huge = good.message;  // height 2^32-1 rows over the data of 8 columns
  const std::uint32_t rows = 0xFFFFFFFFu;
  std::memcpy(huge.data() + 20, &rows, 4);  // after seq, stamp and the 4-byte frame_id "base"
  EXPECT_THROW(io::decodePointCloud2(huge.data(), huge.size(), config, 0), io::DecodeError);
  Bytes empty_rows = pointCloud2(kSec, 0, {{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}}, 12, Bytes{});  // width 0
  std::memcpy(empty_rows.data() + 20, &rows, 4);  // ... in 2^32-1 rows: an empty sweep, at once (fuzz finding)
  EXPECT_TRUE(io::decodePointCloud2(empty_rows.data(), empty_rows.size(), config, 0).points.empty());
  const Bytes imu = imuMessage(kSec, 0, imuAt(1));
  EXPECT_THROW(io::decodeImu(imu.data(), imu.size() - 1, 0), io::DecodeError);
}

}  // namespace
}  // namespace adit::test
