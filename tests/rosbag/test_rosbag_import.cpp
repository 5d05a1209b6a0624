// The bag as a message source (what `adit import rosbag` runs): sweeps and IMU samples in stamp order on
// their channels, within the sweep codec's tolerance; a corrupted chunk costs that chunk and is counted;
// a wrong topic is a one-line error naming the topics the bag has.
#include <gtest/gtest.h>

#include "bag_writer.hpp"
#include "clouds.hpp"
#include "io/io_error.hpp"
#include "msg/convert.hpp"
#include "msg/sweep_codec.hpp"
#include "sources/rosbag_source.hpp"
#include "../io/temp_dir.hpp"

namespace adit::test {
namespace {

constexpr std::uint32_t kSec = 1700000000;

struct Written {
  std::string bytes;
  std::vector<TestCloud> clouds;
  std::vector<std::pair<std::size_t, std::size_t>> chunks;
};

// Ouster sweeps stamped at their start, IMU at 100 Hz recorded between them: the source must put each
// sweep after the IMU samples of its own 0.1 s.
Written writeBag(const std::string& compression) {
  Written out;
  BagWriter w(compression);
  w.addConnection(3, "/os/points", "sensor_msgs/PointCloud2");
  w.addConnection(4, "/os/imu", "sensor_msgs/Imu");
  w.addConnection(5, "/tf", "tf2_msgs/TFMessage");
  for (int k = 0; k < 6; ++k) {
    const std::uint32_t nsec = 100000000u * static_cast<std::uint32_t>(k);
    out.clouds.push_back(k % 2 ? velodyneCloud(kSec, nsec + 100000000u, 120, k) : ousterCloud(kSec, nsec, 128, k));
    w.addMessage(3, std::int64_t{kSec} * 1000000000 + nsec + 100000000, out.clouds.back().message);
    w.addMessage(5, std::int64_t{kSec} * 1000000000 + nsec, Bytes(16, 1));
    for (int i = 0; i < 10; ++i) {
      ImuSample s;
      s.gyro = Eigen::Vector3d(0.0, 0.0, 0.1 * k);
      s.accel = Eigen::Vector3d(0.0, 0.0, 9.8);
      const std::uint32_t t = nsec + 10000000u * static_cast<std::uint32_t>(i) + 5000000u;
      w.addMessage(4, std::int64_t{kSec} * 1000000000 + t + 2000000, imuMessage(kSec, t, s));
    }
    if (k % 2) out.chunks.push_back(w.endChunk());
  }
  out.bytes = w.finish();
  return out;
}

struct Imported {
  std::vector<LidarScan> scans;
  std::vector<ImuSample> imu;
  std::vector<std::int64_t> order;  // utimes in emission order
  runtime::Health health;
};

Imported import(const std::string& path) {
  sources::RosbagSourceConfig config;
  config.lidar_topic = "/os/points";
  config.imu_topic = "/os/imu";
  auto source = sources::makeRosbagSource(path, config);
  Imported out;
  runtime::OutgoingMessage m;
  while (source->next(m)) {
    out.order.push_back(m.utime);
    if (m.channel == "LIDAR_POINTS") {
      adit::lidar_scan_t msg;
      EXPECT_GE(msg.decode(m.data.data(), 0, static_cast<int>(m.data.size())), 0);
      LidarScan scan;
      EXPECT_EQ(msg::decodeSweep(msg, scan), "");
      out.scans.push_back(scan);
    } else {
      EXPECT_EQ(m.channel, "IMU");
      adit::imu_t msg;
      EXPECT_GE(msg.decode(m.data.data(), 0, static_cast<int>(m.data.size())), 0);
      out.imu.push_back(msg::fromMessage(msg));
    }
  }
  out.health = source->health();
  return out;
}

void expectSweep(const LidarScan& got, const TestCloud& want) {
  EXPECT_EQ(got.utime, want.expected_utime);
  ASSERT_EQ(got.points.size(), want.expected.size());
  for (std::size_t i = 0; i < got.points.size(); ++i) {
    const LidarPoint &g = got.points[i], &e = want.expected[i];
    // The LCM sweep codec stores ranges in 2 mm counts and angles in 1e-4 rad (msg/sweep_codec.hpp).
    ASSERT_LE((g.p - e.p).norm(), msg::sweepTolerance(e.p.norm(), msg::kRangeScale)) << i;
    ASSERT_EQ(g.ring, e.ring) << i;
    ASSERT_NEAR(g.dt, e.dt, 1e-6) << i;
  }
}

TEST(RosbagImport, SweepsAndImuInStampOrder) {
  for (const std::string compression : {"none", "bz2", "lz4"}) {
    io::test::TempDir dir;
    const Written bag = writeBag(compression);
    dir.write("run.bag", bag.bytes);
    const Imported r = import(dir.file("run.bag"));
    EXPECT_EQ(r.health.drops, 0) << r.health.last_error;
    ASSERT_EQ(r.scans.size(), 6u) << compression;
    ASSERT_EQ(r.imu.size(), 60u) << compression;
    for (std::size_t k = 0; k < 6; ++k) expectSweep(r.scans[k], bag.clouds[k]);
    EXPECT_TRUE(std::is_sorted(r.order.begin(), r.order.end())) << compression;
    EXPECT_EQ(r.imu[59].gyro.z(), 0.5);
  }
}

TEST(RosbagImport, CorruptChunkIsCountedAndTheRestImported) {
  io::test::TempDir dir;
  Written bag = writeBag("lz4");
  const auto [begin, end] = bag.chunks[1];
  for (std::size_t i = begin + 20; i < end - 20; i += 7) bag.bytes[i] = static_cast<char>(~bag.bytes[i]);
  dir.write("run.bag", bag.bytes);
  const Imported r = import(dir.file("run.bag"));
  EXPECT_EQ(r.health.counters.at("bag_chunk_lost"), 1);
  EXPECT_NE(r.health.last_error.find("chunk 2"), std::string::npos) << r.health.last_error;
  ASSERT_EQ(r.scans.size(), 4u);
  EXPECT_EQ(r.imu.size(), 40u);
  expectSweep(r.scans[0], bag.clouds[0]);
  expectSweep(r.scans[1], bag.clouds[1]);
  expectSweep(r.scans[2], bag.clouds[4]);
  expectSweep(r.scans[3], bag.clouds[5]);
}

TEST(RosbagImport, WrongTopicNamesTheTopicsThere) {
  io::test::TempDir dir;
  dir.write("run.bag", writeBag("none").bytes);
  sources::RosbagSourceConfig config;
  config.lidar_topic = "/velodyne_points";
  try {
    sources::makeRosbagSource(dir.file("run.bag"), config);
    FAIL() << "no error";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no topic /velodyne_points"), std::string::npos) << what;
    EXPECT_NE(what.find("/os/points (sensor_msgs/PointCloud2)"), std::string::npos) << what;
  }
  config.lidar_topic = "/os/imu";
  EXPECT_THROW(sources::makeRosbagSource(dir.file("run.bag"), config), io::ReadError);
}

}  // namespace
}  // namespace adit::test
