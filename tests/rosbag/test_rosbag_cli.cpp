// `adit import rosbag` and `adit info <file.bag>` with the built program: a good bag, a bag with a corrupted
// chunk (log of the rest, status 3), files that are not bags and a wrong topic (status 1, one error line
// naming the file, no log).
#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "../integration/cli_helpers.hpp"
#include "bag_writer.hpp"
#include "clouds.hpp"

namespace adit::test {
namespace {

namespace fs = std::filesystem;

struct Bag {
  std::string bytes;
  std::vector<std::pair<std::size_t, std::size_t>> chunks;
};

Bag writeBag() {
  Bag b;
  BagWriter w("lz4");
  w.addConnection(0, "/points", "sensor_msgs/PointCloud2");
  w.addConnection(1, "/imu", "sensor_msgs/Imu");
  for (int k = 0; k < 4; ++k) {
    const std::uint32_t nsec = 100000000u * static_cast<std::uint32_t>(k) + 100000000u;
    w.addMessage(0, 1700000000LL * 1000000000 + nsec, velodyneCloud(1700000000u, nsec, 90, k).message);
    for (int i = 0; i < 10; ++i)
      w.addMessage(1, 1700000000LL * 1000000000 + nsec + i * 10000000, imuMessage(1700000000u, nsec + i * 10000000u, ImuSample{}));
    if (k % 2) b.chunks.push_back(w.endChunk());
  }
  b.bytes = w.finish();
  return b;
}

int errorLines(const std::string& output, const std::string& named, bool& names_file) {
  std::istringstream lines(output);
  std::string line;
  int n = 0;
  names_file = false;
  while (std::getline(lines, line)) {
    if (line.find(" error ") == std::string::npos) continue;  // the log level, not "(0 errors, ...)"
    ++n;
    names_file = names_file || line.find(named) != std::string::npos;
  }
  return n;
}

class RosbagCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = freshDir("rosbag_cli"); }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& bytes) const { std::ofstream(dir_ / name, std::ios::binary) << bytes; }
  int adit(const std::string& args) const { return run(bin("adit") + " " + args, dir_ / "out.txt"); }
  std::string output() const { return slurp(dir_ / "out.txt"); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(RosbagCli, InfoAndImport) {
  write("run.bag", writeBag().bytes);
  ASSERT_EQ(adit("info " + path("run.bag")), 0) << output();
  const std::string info = output();
  EXPECT_NE(info.find("sensor_msgs/PointCloud2"), std::string::npos) << info;
  EXPECT_NE(info.find("2 chunks, 44 messages"), std::string::npos) << info;
  ASSERT_EQ(adit("import rosbag " + path("run.bag") + " --lidar-topic /points --imu-topic /imu -o " + path("out.lcmlog")), 0)
      << output();
  const auto log = payloads(path("out.lcmlog"));
  EXPECT_EQ(log.at("LIDAR_POINTS").size(), 4u);
  EXPECT_EQ(log.at("IMU").size(), 40u);
}

TEST_F(RosbagCli, CorruptChunkImportsTheRestWithStatus3) {
  Bag bag = writeBag();
  for (std::size_t i = bag.chunks[0].first + 30; i < bag.chunks[0].second - 30; i += 5) bag.bytes[i] = static_cast<char>(~bag.bytes[i]);
  write("bad.bag", bag.bytes);
  EXPECT_EQ(adit("import rosbag " + path("bad.bag") + " --lidar-topic /points --imu-topic /imu -o " + path("out.lcmlog")), 3);
  bool names = false;
  EXPECT_LE(errorLines(output(), "bad.bag", names), 2) << output();
  EXPECT_TRUE(names) << output();
  const auto log = payloads(path("out.lcmlog"));
  EXPECT_EQ(log.at("LIDAR_POINTS").size(), 2u);
  EXPECT_EQ(log.at("IMU").size(), 20u);
  EXPECT_EQ(adit("info " + path("bad.bag")), 3);
}

TEST_F(RosbagCli, NotABagOrWrongTopicIsOneLine) {
  std::mt19937 rng(5);
  std::string random(6000, '\0');
  for (char& c : random) c = static_cast<char>(rng());
  const std::string good = writeBag().bytes;
  const std::pair<std::string, std::string> cases[] = {
      {"empty", ""}, {"random", random}, {"cut in header", good.substr(0, 2000)}, {"version line and noise", "#ROSBAG V2.0\n" + random}};
  for (const auto& [what, bytes] : cases) {
    write("in.bag", bytes);
    EXPECT_EQ(adit("import rosbag " + path("in.bag") + " --lidar-topic /points -o " + path("x.lcmlog")), 1) << what;
    bool names = false;
    EXPECT_EQ(errorLines(output(), "in.bag", names), 1) << what << ": " << output();
    EXPECT_TRUE(names) << what << ": " << output();
    EXPECT_FALSE(fs::exists(dir_ / "x.lcmlog")) << what;
  }
  write("run.bag", good);
  EXPECT_EQ(adit("import rosbag " + path("run.bag") + " --lidar-topic /velodyne_points -o " + path("x.lcmlog")), 1);
  EXPECT_NE(output().find("it has /points (sensor_msgs/PointCloud2), /imu (sensor_msgs/Imu)"), std::string::npos) << output();
  EXPECT_FALSE(fs::exists(dir_ / "x.lcmlog"));
}

}  // namespace
}  // namespace adit::test
