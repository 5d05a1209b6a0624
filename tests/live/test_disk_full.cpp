// Disk full while saving a map or a checkpoint: the failed write is counted, leaves no partial or temporary
// file, what was written before stays intact and loadable, the run goes on, and it writes again (and a restart
// resumes) once there is space. Needs a tiny file system of its own: tests/live/disk_full_save.sh mounts a
// tmpfs and names it in $ADIT_FULL_DISK_DIR; without it the tests skip.
#include "node_harness.hpp"
#include "nodes/registry.hpp"

#include <adit/command_t.hpp>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <set>

namespace fs = std::filesystem;
using adit::test::counter;

namespace {

// A fresh folder on the small file system, or "" (the test skips).
std::string folderOnSmallDisk(const std::string& name) {
  const char* dir = std::getenv("ADIT_FULL_DISK_DIR");
  if (!dir || !*dir) return "";
  const fs::path path = fs::path(dir) / name;
  fs::remove_all(path);
  fs::create_directories(path);
  return path.string();
}

// Takes every free byte of the file system holding `dir`; removing the returned file gives them back.
std::string fillDisk(const std::string& dir) {
  const std::string path = dir + "/filler";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  EXPECT_GE(fd, 0);
  std::vector<char> block(64 * 1024, 'f');
  for (std::size_t size = block.size(); size > 0; size /= 2)
    while (::write(fd, block.data(), size) == static_cast<ssize_t>(size)) {
    }
  ::close(fd);
  EXPECT_FALSE(std::ofstream(dir + "/probe") << "x" << std::flush) << "the disk is not full";
  fs::remove(dir + "/probe");
  return path;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::set<std::string> filesIn(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

adit::command_t saveMap(const std::string& name) {
  adit::command_t c{};
  c.command = "save_map";
  c.argument = name;
  return c;
}

TEST(DiskFull, SaveMapFailsCleanlyAndWorksOnceThereIsSpace) {
  const std::string run = folderOnSmallDisk("save_map");
  if (run.empty()) GTEST_SKIP() << "no small disk ($ADIT_FULL_DISK_DIR; ctest live_disk_full mounts one)";
  auto node = adit::nodes::makeNode("loop_closer", adit::Config{});
  node->useRunFolder(adit::test::liveFolder(run));
  adit::test::Collector sink;
  for (int k = 0; k < 5; ++k) adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k), sink);
  adit::test::deliver(*node, "MAPPER_COMMAND", saveMap("first"), sink);
  ASSERT_EQ(counter(*node, "maps_saved"), 1);
  const std::string first_map = readFile(run + "/first.pcd");

  const std::string filler = fillDisk(run);
  const std::set<std::string> before = filesIn(run);
  adit::test::deliver(*node, "MAPPER_COMMAND", saveMap("second"), sink);
  EXPECT_EQ(counter(*node, "save_failed"), 1);
  EXPECT_NE(node->health().last_error.find("No space left"), std::string::npos) << node->health().last_error;
  EXPECT_EQ(filesIn(run), before) << "a failed save left a file behind";
  EXPECT_EQ(readFile(run + "/first.pcd"), first_map);

  // The run goes on and saves once there is space again.
  adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(5), sink);
  fs::remove(filler);
  adit::test::deliver(*node, "MAPPER_COMMAND", saveMap("second"), sink);
  EXPECT_EQ(counter(*node, "maps_saved"), 2);
  EXPECT_GT(fs::file_size(run + "/second.pcd"), fs::file_size(run + "/first.pcd")) << "six keyframes, not five";
}

TEST(DiskFull, CheckpointsKeepThePreviousOneAndARestartResumesFromIt) {
  const std::string run = folderOnSmallDisk("checkpoint");
  if (run.empty()) GTEST_SKIP() << "no small disk ($ADIT_FULL_DISK_DIR; ctest live_disk_full mounts one)";
  const adit::Config config = adit::Config::fromYamlString("loop:\n  node:\n    checkpoint_keyframes: 4\n");
  adit::test::Collector sink;
  std::string checkpoint;
  std::string filler;
  {
    auto node = adit::nodes::makeNode("loop_closer", config);
    node->useRunFolder(adit::test::liveFolder(run));
    for (int k = 0; k < 8; ++k) adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k), sink);
    node->finish(sink);  // waits for the writer: checkpoint of 8 keyframes, products saved
    EXPECT_EQ(counter(*node, "checkpoint_failed"), 0);
    checkpoint = readFile(run + "/loop_closer.ckpt");
  }
  {
    // A restart finds the disk full: it resumes, maps on, and every checkpoint fails (counted).
    filler = fillDisk(run);
    auto node = adit::nodes::makeNode("loop_closer", config);
    node->useRunFolder(adit::test::liveFolder(run, "run-1", 1));
    EXPECT_EQ(counter(*node, "recovered_keyframes"), 8);
    const std::set<std::string> before = filesIn(run);
    for (int k = 8; k < 16; ++k) adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k), sink);
    node->finish(sink);
    EXPECT_GE(counter(*node, "checkpoint_failed"), 1);
    EXPECT_EQ(counter(*node, "keyframes"), 16) << "the run went on";
    EXPECT_EQ(filesIn(run), before) << "a failed write left a file behind";
    EXPECT_EQ(readFile(run + "/loop_closer.ckpt"), checkpoint) << "the previous checkpoint was damaged";
  }
  fs::remove(filler);
  {
    // With space again, the next restart resumes from the last good checkpoint (8 keyframes: the log's
    // records appended while the disk was full were cut off) and checkpoints again.
    auto node = adit::nodes::makeNode("loop_closer", config);
    node->useRunFolder(adit::test::liveFolder(run, "run-1", 2));
    EXPECT_EQ(counter(*node, "checkpoint_refused"), 0) << node->health().last_error;
    EXPECT_EQ(counter(*node, "recovered_keyframes"), 8);
    for (int k = 16; k < 20; ++k) adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k), sink);
    node->finish(sink);
    EXPECT_EQ(counter(*node, "checkpoint_failed"), 0) << node->health().last_error;
  }
  auto resumed = adit::nodes::makeNode("loop_closer", config);
  resumed->useRunFolder(adit::test::liveFolder(run, "run-1", 3));
  EXPECT_EQ(counter(*resumed, "recovered_keyframes"), 12);
}

TEST(DiskFull, SpaceFreedDuringTheRunMakesTheNextCheckpointWholeAgain) {
  const std::string run = folderOnSmallDisk("freed");
  if (run.empty()) GTEST_SKIP() << "no small disk ($ADIT_FULL_DISK_DIR; ctest live_disk_full mounts one)";
  const adit::Config config = adit::Config::fromYamlString("loop:\n  node:\n    checkpoint_keyframes: 4\n");
  adit::test::Collector sink;
  {
    auto node = adit::nodes::makeNode("loop_closer", config);
    node->useRunFolder(adit::test::liveFolder(run));
    for (int k = 0; k < 4; ++k) adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k), sink);
    const std::string filler = fillDisk(run);
    for (int k = 4; k < 12; ++k) adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k), sink);
    fs::remove(filler);  // e.g. old recordings deleted while the robot drives
    for (int k = 12; k < 16; ++k) adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k), sink);
    node->finish(sink);
  }
  // Whatever the failed appends left in the keyframe log was cut: a restart recovers every keyframe.
  auto resumed = adit::nodes::makeNode("loop_closer", config);
  resumed->useRunFolder(adit::test::liveFolder(run, "run-1", 1));
  EXPECT_EQ(counter(*resumed, "checkpoint_refused"), 0) << resumed->health().last_error;
  EXPECT_EQ(counter(*resumed, "recovered_keyframes"), 16);
}

TEST(DiskFull, MapperCheckpointFailsCleanly) {
  const std::string run = folderOnSmallDisk("mapper");
  if (run.empty()) GTEST_SKIP() << "no small disk ($ADIT_FULL_DISK_DIR; ctest live_disk_full mounts one)";
  adit::test::Collector sink;
  {
    auto mapper = adit::nodes::makeNode("mapper", adit::Config{});
    mapper->useRunFolder(adit::test::liveFolder(run));
    for (int k = 0; k < 6; ++k) adit::test::deliver(*mapper, "ODOM_SCAN", adit::test::mappedMessage(k, 0.2), sink);
    mapper->finish(sink);
  }
  const std::string checkpoint = readFile(run + "/mapper.ckpt");
  ASSERT_FALSE(checkpoint.empty());
  const std::string filler = fillDisk(run);
  {
    auto mapper = adit::nodes::makeNode("mapper", adit::Config{});
    mapper->useRunFolder(adit::test::liveFolder(run, "run-1", 1));
    EXPECT_EQ(counter(*mapper, "restarted"), 1);
    const std::set<std::string> before = filesIn(run);
    for (int k = 6; k < 12; ++k) adit::test::deliver(*mapper, "ODOM_SCAN", adit::test::mappedMessage(k, 0.2), sink);
    mapper->finish(sink);
    EXPECT_GE(counter(*mapper, "checkpoint_failed"), 1);
    EXPECT_EQ(counter(*mapper, "registration_failed"), 0) << "the mapper went on mapping";
    EXPECT_EQ(filesIn(run), before) << "a failed write left a file behind";
    EXPECT_EQ(readFile(run + "/mapper.ckpt"), checkpoint);
  }
  fs::remove(filler);
  auto mapper = adit::nodes::makeNode("mapper", adit::Config{});
  mapper->useRunFolder(adit::test::liveFolder(run, "run-1", 2));
  EXPECT_EQ(counter(*mapper, "restarted"), 1);
  EXPECT_EQ(counter(*mapper, "checkpoint_refused"), 0);
}

}  // namespace
