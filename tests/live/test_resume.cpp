// A restarted stage resumes from its checkpoint (loop closer: keyframes, graph, trajectory; mapper: local map
// and drift correction), reports it on STATUS, and refuses a checkpoint of another run or a damaged one.
#include "loop/loop_closer.hpp"
#include "node_harness.hpp"
#include "nodes/registry.hpp"

#include <gtest/gtest.h>

#include <fstream>

namespace fs = std::filesystem;
using adit::test::counter;

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Runs a loop closer over sweeps [0, n) and stops it cleanly (checkpoint + products in `dir`).
std::unique_ptr<adit::runtime::Node> runLoopCloser(const adit::runtime::RunFolder& folder, int first, int n) {
  auto node = adit::nodes::makeNode("loop_closer", adit::Config{});
  node->useRunFolder(folder);
  adit::test::Collector sink;
  for (int k = first; k < first + n; ++k) adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k), sink);
  node->finish(sink);
  return node;
}

TEST(Resume, LoopCloserStateRoundTripsExactly) {
  adit::LoopCloser closer;
  for (int k = 0; k < 12; ++k) {
    const adit::odometry_t m = adit::test::mappedMessage(k);
    closer.process(adit::msg::fromMessage(m), adit::msg::featuresOf(m).cloud);
  }
  const std::string bytes = closer.saveState();
  std::vector<std::string> records;
  for (int k = 0; k < 12; ++k) records.push_back(closer.keyframeRecord(k));
  adit::LoopCloser restored;
  ASSERT_TRUE(restored.restoreState(bytes, records));
  EXPECT_EQ(restored.saveState(), bytes);
  EXPECT_EQ(restored.keyframeRecord(11), records[11]);
  EXPECT_EQ(restored.keyframes().size(), 12u);
  EXPECT_FALSE(restored.restoreState(bytes.substr(0, bytes.size() - 3), records));
  records.pop_back();
  EXPECT_FALSE(restored.restoreState(bytes, records)) << "a missing keyframe record";
  EXPECT_EQ(restored.keyframes().size(), 12u) << "a failed restore must leave the state alone";
}

TEST(Resume, RestartedLoopCloserKeepsItsKeyframesAndReportsIt) {
  adit::test::TempFolder run;
  runLoopCloser(adit::test::liveFolder(run.path()), 0, 10);
  const std::string map_before = readFile(run.file("map.pcd"));
  auto restarted = runLoopCloser(adit::test::liveFolder(run.path(), "run-1", 1), 10, 0);
  EXPECT_EQ(counter(*restarted, "restarted"), 1);
  EXPECT_EQ(counter(*restarted, "recovered_keyframes"), 10);
  EXPECT_EQ(restarted->state(), "restarted");
  EXPECT_EQ(readFile(run.file("map.pcd")), map_before) << "the restarted owner saves the same map";
  // It goes on from there: 5 more sweeps, 15 keyframes.
  auto more = runLoopCloser(adit::test::liveFolder(run.path(), "run-1", 2), 10, 5);
  EXPECT_EQ(counter(*more, "keyframes"), 15);
}

TEST(Resume, CheckpointOfAnotherRunOrDamagedIsRefusedWithAFreshStart) {
  adit::test::TempFolder run;
  runLoopCloser(adit::test::liveFolder(run.path(), "run-1"), 0, 5);
  auto other = runLoopCloser(adit::test::liveFolder(run.path(), "run-2", 1), 100, 0);
  EXPECT_EQ(counter(*other, "checkpoint_refused"), 1);
  EXPECT_EQ(counter(*other, "restarted"), 1) << "restarted, though with nothing recovered";
  EXPECT_EQ(counter(*other, "recovered_keyframes"), 0);
  EXPECT_NE(other->health().last_error.find("run-1"), std::string::npos) << other->health().last_error;

  const std::string path = run.file("loop_closer.ckpt");
  const std::string good = readFile(path);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << good.substr(0, good.size() / 2);
  auto truncated = runLoopCloser(adit::test::liveFolder(run.path(), "run-1", 1), 100, 3);
  EXPECT_EQ(counter(*truncated, "checkpoint_refused"), 1);
  EXPECT_EQ(counter(*truncated, "keyframes"), 3) << "fresh start";
}

TEST(Resume, KeyframesWrittenAfterTheCheckpointAreCutAndATornLogIsRefused) {
  adit::test::TempFolder run;
  runLoopCloser(adit::test::liveFolder(run.path()), 0, 10);  // checkpoint on stop: 10 keyframes
  const std::string checkpoint = readFile(run.file("loop_closer.ckpt"));
  auto later = runLoopCloser(adit::test::liveFolder(run.path(), "run-1", 1), 10, 15);  // 25 on disk now
  std::ofstream(run.file("loop_closer.ckpt"), std::ios::binary | std::ios::trunc) << checkpoint;  // "crash" at 10
  auto resumed = runLoopCloser(adit::test::liveFolder(run.path(), "run-1", 2), 10, 5);
  EXPECT_EQ(counter(*resumed, "recovered_keyframes"), 10);
  EXPECT_EQ(counter(*resumed, "keyframes"), 15);
  auto again = runLoopCloser(adit::test::liveFolder(run.path(), "run-1", 3), 15, 0);
  EXPECT_EQ(counter(*again, "recovered_keyframes"), 15) << "the log was cut at 10 and continued";

  const std::string log = readFile(run.file("loop_closer.keyframes"));
  std::ofstream(run.file("loop_closer.keyframes"), std::ios::binary | std::ios::trunc) << log.substr(0, log.size() / 2);
  auto torn = runLoopCloser(adit::test::liveFolder(run.path(), "run-1", 4), 15, 2);
  EXPECT_EQ(counter(*torn, "checkpoint_refused"), 1);
  EXPECT_EQ(counter(*torn, "keyframes"), 2) << "fresh start";
}

// Killed before its first checkpoint: it starts fresh, and STATUS still says it was restarted (the live_restart
// test under sanitizers, where the loop closer was killed before it had written one, showed no sign of the crash).
TEST(Resume, ARestartWithNoCheckpointIsStillReported) {
  adit::test::TempFolder run;
  for (const std::string stage : {"loop_closer", "mapper", "odometry"}) {
    auto node = adit::nodes::makeNode(stage, adit::Config{});
    node->useRunFolder(adit::test::liveFolder(run.path(), "run-1", 1));
    EXPECT_EQ(counter(*node, "restarted"), 1) << stage;
    EXPECT_EQ(counter(*node, "checkpoint_refused"), 0) << stage;
    EXPECT_EQ(node->state(), "restarted") << stage;
  }
}

TEST(Resume, NoResumeWithoutAGivenFolderOrARestart) {
  adit::test::TempFolder run;
  runLoopCloser(adit::test::liveFolder(run.path()), 0, 5);
  adit::runtime::RunFolder folder = adit::test::liveFolder(run.path());
  folder.given = false;  // the default folder: a checkpoint there may be an old run's
  auto node = runLoopCloser(folder, 100, 0);
  EXPECT_EQ(counter(*node, "restarted"), 0);
  EXPECT_EQ(counter(*node, "checkpoint_refused"), 0);
}

TEST(Resume, RestartedMapperReseedsItsLocalMap) {
  adit::test::TempFolder run;
  adit::test::Collector sink;
  std::int64_t points = 0;
  {
    auto mapper = adit::nodes::makeNode("mapper", adit::Config{});
    mapper->useRunFolder(adit::test::liveFolder(run.path()));
    for (int k = 0; k < 8; ++k) adit::test::deliver(*mapper, "ODOM_SCAN", adit::test::mappedMessage(k, 0.2), sink);
    mapper->finish(sink);
    EXPECT_GE(counter(*mapper, "checkpoints"), 1);
  }
  auto mapper = adit::nodes::makeNode("mapper", adit::Config{});
  mapper->useRunFolder(adit::test::liveFolder(run.path(), "run-1", 1));
  points = counter(*mapper, "recovered_map_points");
  EXPECT_EQ(counter(*mapper, "restarted"), 1);
  EXPECT_GT(points, 1000);
  // The next sweep is registered against the restored map (not treated as the first one).
  sink.messages.clear();
  adit::test::deliver(*mapper, "ODOM_SCAN", adit::test::mappedMessage(8, 0.2), sink);
  ASSERT_EQ(sink.messages["ODOM_MAPPED"].size(), 1u);
  adit::odometry_t out;
  const auto& bytes = sink.messages["ODOM_MAPPED"][0];
  ASSERT_GT(out.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  EXPECT_NEAR(out.position[0], 8 * 0.2, 0.05);
  EXPECT_EQ(counter(*mapper, "registration_failed"), 0);
}

}  // namespace
