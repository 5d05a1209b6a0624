// Commands are received from anyone on the bus: save_map may only name a plain file inside the run folder;
// anything else is refused, counted and logged, and nothing is written.
#include "node_harness.hpp"
#include "nodes/registry.hpp"
#include "runtime/command_auth.hpp"
#include "runtime/process.hpp"
#include "runtime/run_folder.hpp"

#include <adit/command_t.hpp>
#include <gtest/gtest.h>

namespace fs = std::filesystem;
using adit::test::counter;

namespace {

adit::command_t command(const std::string& name, const std::string& argument) {
  adit::command_t c{};
  c.header.utime = 0;
  c.header.seq = 0;
  c.command = name;
  c.argument = argument;
  return c;
}

// A loop closer (the map owner, which receives MAPPER_COMMAND) writing into `run`, a folder of its own.
struct MapOwnerInRunFolder {
  adit::test::TempFolder parent;
  std::string run = parent.file("run");
  std::unique_ptr<adit::runtime::Node> node = adit::nodes::makeNode("loop_closer", adit::Config{});
  adit::test::Collector sink;
  MapOwnerInRunFolder() {
    fs::create_directory(run);
    node->useRunFolder(adit::test::liveFolder(run));
  }
};

std::size_t filesIn(const std::string& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) n += e.is_regular_file() ? 1 : 0;
  return n;
}

TEST(Commands, SaveMapWritesTheThreeProductsIntoTheRunFolder) {
  MapOwnerInRunFolder owner;
  auto& [parent, run, node, sink] = owner;
  for (int k = 0; k < 5; ++k) adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k), sink);
  adit::test::deliver(*node, "MAPPER_COMMAND", command("save_map", ""), sink);
  adit::test::deliver(*node, "MAPPER_COMMAND", command("save_map", "before_loop.pcd"), sink);
  for (const char* f : {"map.pcd", "trajectory.tum", "pose_graph.g2o", "before_loop.pcd", "before_loop.tum",
                        "before_loop.g2o"})
    EXPECT_TRUE(fs::exists(fs::path(run) / f)) << f;
  EXPECT_EQ(counter(*node, "maps_saved"), 2);
  EXPECT_GT(fs::file_size(fs::path(run) / "map.pcd"), 1000u);
}

TEST(Commands, HostilePathsAreRefusedAndCounted) {
  MapOwnerInRunFolder owner;
  auto& [parent, run, node, sink] = owner;
  adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(0), sink);
  const std::vector<std::string> hostile{
      parent.file("evil.pcd"), "../evil.pcd", "../../etc/passwd", "sub/map.pcd", "..", ".", ".hidden", "-rf",
      "a\\b", "map\n.pcd", std::string(65, 'a'), "m\xc3\xa9.pcd", "map .pcd",
      "~root", "$HOME"};
  // (A NUL cannot be sent: LCM strings end at the first one, so "map\0x" arrives as the harmless "map".)
  for (const std::string& arg : hostile) adit::test::deliver(*node, "MAPPER_COMMAND", command("save_map", arg), sink);
  EXPECT_EQ(counter(*node, "command_refused"), static_cast<std::int64_t>(hostile.size()));
  EXPECT_EQ(counter(*node, "maps_saved"), 0);
  EXPECT_EQ(filesIn(parent.path()), 0u) << "a refused command wrote a file";
  EXPECT_NE(node->health().last_error.find("refused"), std::string::npos);
  adit::test::deliver(*node, "MAPPER_COMMAND", command("rm", "-rf /"), sink);
  EXPECT_EQ(counter(*node, "unknown_command"), 1);
}

adit::command_t signedCommand(const adit::runtime::CommandKey& key, const std::string& argument, std::int64_t counter) {
  adit::command_t c = command("save_map", argument);
  c.counter = counter;
  const adit::runtime::CommandMac mac = adit::runtime::commandMac(key, "MAPPER_COMMAND", c.command, argument, counter);
  c.mac.assign(mac.begin(), mac.end());
  c.mac_size = static_cast<std::int32_t>(c.mac.size());
  return c;
}

TEST(Commands, WithAKeyOnlySignedCommandsAreObeyed) {
  MapOwnerInRunFolder owner;
  auto& [parent, run, node, sink] = owner;
  const adit::runtime::CommandKey key(32, 0x5a);
  node->requireSignedCommands(key);
  adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(0), sink);
  const std::int64_t now = adit::runtime::wallUtime();

  adit::test::deliver(*node, "MAPPER_COMMAND", command("save_map", "unsigned"), sink);
  adit::test::deliver(*node, "MAPPER_COMMAND", signedCommand(adit::runtime::CommandKey(32, 1), "other_key", now), sink);
  adit::command_t altered = signedCommand(key, "signed", now);
  altered.argument = "altered";
  adit::test::deliver(*node, "MAPPER_COMMAND", altered, sink);
  adit::test::deliver(*node, "MAPPER_COMMAND", signedCommand(key, "old", now - 3'600'000'000LL), sink);
  EXPECT_EQ(filesIn(run), 0u) << "a command that is not authentic wrote a file";

  const adit::command_t good = signedCommand(key, "signed", now);
  adit::test::deliver(*node, "MAPPER_COMMAND", good, sink);
  adit::test::deliver(*node, "MAPPER_COMMAND", good, sink);  // recorded and sent again
  EXPECT_TRUE(fs::exists(fs::path(run) / "signed.pcd"));
  EXPECT_EQ(counter(*node, "maps_saved"), 1);
  EXPECT_EQ(counter(*node, "command_unsigned"), 1);
  EXPECT_EQ(counter(*node, "command_bad_mac"), 2);
  EXPECT_EQ(counter(*node, "command_stale"), 1);
  EXPECT_EQ(counter(*node, "command_replayed"), 1);
  // A signed command still names only a plain file in the run folder.
  adit::test::deliver(*node, "MAPPER_COMMAND", signedCommand(key, "../evil", now + 1), sink);
  EXPECT_EQ(counter(*node, "command_refused"), 1);
  // A mac of the wrong size is not a message at all.
  adit::command_t bad_size = signedCommand(key, "x", now + 2);
  bad_size.mac.pop_back();
  bad_size.mac_size = 31;
  adit::test::deliver(*node, "MAPPER_COMMAND", bad_size, sink);
  EXPECT_EQ(counter(*node, "maps_saved"), 1);
}

TEST(Commands, PlainFileNameRules) {
  using adit::runtime::plainFileNameProblem;
  for (const char* ok : {"map.pcd", "run_2024-01-01.pcd", "a", "A.b.c"}) EXPECT_EQ(plainFileNameProblem(ok), "") << ok;
  for (const char* bad : {"", "/map.pcd", "a/b", "..", "../x", ".x", "-x", "x y", "x;y"})
    EXPECT_NE(plainFileNameProblem(bad), "") << bad;
  EXPECT_NE(plainFileNameProblem(std::string(adit::runtime::kMaxCommandFileName + 1, 'a')), "");
  EXPECT_EQ(plainFileNameProblem(std::string(adit::runtime::kMaxCommandFileName, 'a')), "");
}

TEST(Commands, AnUnwritableRunFolderIsAnErrorNotACrash) {
  adit::test::TempFolder parent;
  auto node = adit::nodes::makeNode("loop_closer", adit::Config{});
  node->useRunFolder(adit::test::liveFolder(parent.file("missing/run")));
  adit::test::Collector sink;
  adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(0), sink);
  adit::test::deliver(*node, "MAPPER_COMMAND", command("save_map", ""), sink);
  EXPECT_EQ(counter(*node, "save_failed"), 1);
}

}  // namespace

// set_pose on RELOC_COMMAND: the relocaliser takes the operator's guess of where the robot is in the saved map
// only as five (or four) finite numbers with a positive radius, and only when it has a map; anything else is
// refused and counted.
TEST(Commands, SetPoseIsTakenOnlyAsFiniteNumbersAndOnlyWithAMap) {
  MapOwnerInRunFolder owner;
  auto& [parent, run, node, sink] = owner;
  for (int k = 0; k < 30; ++k) adit::test::deliver(*node, "ODOM_MAPPED", adit::test::mappedMessage(k), sink);
  adit::test::deliver(*node, "MAPPER_COMMAND", command("save_bundle", "corridor"), sink);
  ASSERT_EQ(counter(*node, "bundles_saved"), 1);

  adit::Config config;
  config.set("reloc.prior_map", (fs::path(run) / "corridor").string());
  const auto reloc = adit::nodes::makeNode("relocaliser", config);
  ASSERT_EQ(reloc->state(), "relocalising");
  for (const char* good : {"12.5 0 0 90", "1 -2 0.5 -45 8"})
    adit::test::deliver(*reloc, "RELOC_COMMAND", command("set_pose", good), sink);
  EXPECT_EQ(counter(*reloc, "poses_set"), 2);
  for (const char* bad : {"", "1 2 0", "1 2 0 nan", "1 2 0 90 -3", "1 2 0 90 0", "x y z h", "1 2 0 90 4 5", "1e999 0 0 0",
                          "1 2 0 90deg"})
    adit::test::deliver(*reloc, "RELOC_COMMAND", command("set_pose", bad), sink);
  EXPECT_EQ(counter(*reloc, "command_refused"), 9);
  adit::test::deliver(*reloc, "RELOC_COMMAND", command("save_map", ""), sink);
  EXPECT_EQ(counter(*reloc, "unknown_command"), 1);
  EXPECT_EQ(counter(*reloc, "poses_set"), 2);

  const auto without_map = adit::nodes::makeNode("relocaliser", adit::Config{});
  adit::test::deliver(*without_map, "RELOC_COMMAND", command("set_pose", "1 2 0 90"), sink);
  EXPECT_EQ(counter(*without_map, "command_refused"), 1);
  EXPECT_EQ(counter(*without_map, "poses_set"), 0);
}
