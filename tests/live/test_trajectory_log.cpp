// The loop closer's per-sweep trajectory in a live run (nodes/trajectory_log.hpp): checkpoints append only the
// new poses, memory keeps only what the log lacks, and the whole trajectory comes back exactly, also after a
// restart from a checkpoint older than the log's end.
#include "node_harness.hpp"
#include "nodes/products.hpp"
#include "nodes/registry.hpp"
#include "nodes/trajectory_log.hpp"

#include <gtest/gtest.h>

#include <fstream>

using adit::nodes::TrajectoryLog;

namespace {

adit::StampedPose poseAt(int k) {
  adit::StampedPose p;
  p.utime = 1'000'000 + std::int64_t{k} * 100'000;
  p.pose.translation() = Eigen::Vector3d(0.1 * k, std::sin(0.01 * k), 0.001 * k);
  p.pose.linear() = Eigen::AngleAxisd(0.003 * k, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return p;
}

// `n` poses pushed, a checkpoint (unwritten + write) every `every` of them, release once a pose.
void drive(TrajectoryLog& log, int from, int n, int every, const std::string& path,
           std::vector<std::size_t>* lengths = nullptr) {
  for (int k = from; k < from + n; ++k) {
    log.push_back(poseAt(k));
    if ((k + 1) % every == 0) {
      const TrajectoryLog::Chunk chunk = log.unwritten();
      log.write(chunk, path, "run-1");
      if (lengths) lengths->push_back(chunk.first + chunk.poses.size());
    }
    log.release();
  }
}

void expectPoses(const adit::Trajectory& t, int n) {
  ASSERT_EQ(t.size(), static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    EXPECT_EQ(t[static_cast<std::size_t>(k)].utime, poseAt(k).utime) << k;
    EXPECT_TRUE(t[static_cast<std::size_t>(k)].pose.isApprox(poseAt(k).pose, 0)) << k;
  }
}

TEST(TrajectoryLog, PosesInTheLogLeaveMemoryAndComeBackWhole) {
  adit::test::TempFolder dir;
  const std::string path = dir.file("loop_closer.trajectory");
  TrajectoryLog log;
  drive(log, 0, 5000, 37, path);
  EXPECT_EQ(log.size(), 5000u);
  EXPECT_LT(log.inMemory(), 1000u + 37u) << "what the log holds left memory (in batches of 1000)";
  EXPECT_EQ(log.back().utime, poseAt(4999).utime);
  const TrajectoryLog::Chunk left = log.unwritten();
  EXPECT_EQ(left.first, 4995u) << "the last checkpoint was at 4995 poses (135 x 37)";
  expectPoses(log.all(path, "run-1"), 5000);
  // Without a log (replay) nothing leaves memory and nothing is read.
  TrajectoryLog replay;
  for (int k = 0; k < 3000; ++k) {
    replay.push_back(poseAt(k));
    replay.release();
  }
  expectPoses(replay.all(dir.file("none"), "run-1"), 3000);
  EXPECT_EQ(replay.inMemory(), 3000u);
}

TEST(TrajectoryLog, RestoresTheCheckpointsLengthAndCutsTheRest) {
  adit::test::TempFolder dir;
  const std::string path = dir.file("loop_closer.trajectory");
  TrajectoryLog log;
  std::vector<std::size_t> lengths;
  drive(log, 0, 3000, 100, path, &lengths);
  // A restart from the checkpoint at 2000 poses: the log's records after it are cut, the run goes on.
  TrajectoryLog resumed;
  ASSERT_EQ(resumed.restore(path, "run-1", 2000), "");
  EXPECT_EQ(resumed.size(), 2000u);
  drive(resumed, 2000, 1500, 100, path);
  expectPoses(resumed.all(path, "run-1"), 3500);
  TrajectoryLog again;
  ASSERT_EQ(again.restore(path, "run-1", 3500), "");
  expectPoses(again.all(path, "run-1"), 3500);
  // Refused, and left as it was: a length that is not a checkpoint's, another run's log, a torn log.
  TrajectoryLog refused;
  EXPECT_NE(refused.restore(path, "run-1", 2050), "");
  EXPECT_NE(refused.restore(path, "run-2", 2000), "");
  EXPECT_NE(refused.restore(path, "run-1", 9000), "");
  EXPECT_EQ(refused.size(), 0u);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
  EXPECT_NE(refused.restore(path, "run-1", 3500), "");
  EXPECT_THROW(again.all(path, "run-1"), std::runtime_error) << "poses the log lost: an error, not a short trajectory";
}

// Through the stage: 1,300 sweeps live (a checkpoint every 10 keyframes), then a restart that saves again. The
// trajectory.tum of both is the one a replay (no run folder, everything in memory) writes.
TEST(TrajectoryLog, ALiveLoopClosersTrajectoryIsTheReplays) {
  adit::test::TempFolder live_dir, replay_dir;
  auto run = [](const adit::runtime::RunFolder* folder, int first, int n) {
    auto node = adit::nodes::makeNode("loop_closer", adit::Config{});
    if (folder) node->useRunFolder(*folder);
    adit::test::Collector sink;
    for (int k = first; k < first + n; ++k)
      adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k, 0.05), sink);
    node->finish(sink);
    return node;
  };
  const adit::runtime::RunFolder live = adit::test::liveFolder(live_dir.path());
  auto first = run(&live, 0, 1300);
  EXPECT_LT(adit::test::counter(*first, "trajectory_poses_in_memory"), 400) << "the first 1,000 poses left memory";
  auto replay = run(nullptr, 0, 1300);
  dynamic_cast<adit::nodes::WritesProducts&>(*replay).writeProducts(replay_dir.path());
  auto read = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  };
  const std::string expected = read(replay_dir.file("trajectory.tum"));
  ASSERT_GT(std::count(expected.begin(), expected.end(), '\n'), 1250);
  EXPECT_EQ(read(live_dir.file("trajectory.tum")), expected);
  std::filesystem::remove(live_dir.file("trajectory.tum"));
  const adit::runtime::RunFolder restarted = adit::test::liveFolder(live_dir.path(), "run-1", 1);
  auto again = run(&restarted, 1300, 0);
  EXPECT_EQ(adit::test::counter(*again, "checkpoint_refused"), 0) << again->health().last_error;
  EXPECT_EQ(read(live_dir.file("trajectory.tum")), expected) << "the restarted loop closer saves the same trajectory";
}

}  // namespace
