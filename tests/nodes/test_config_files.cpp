// The configuration files under launch/ against the code: launch/config/pipeline.yaml lists exactly the
// keys the stages read, each with its built-in default, and every YAML file under launch/ loads through
// every reader of its sections (pipeline validation, lidar driver, simulator, launcher).
#include "core/config.hpp"
#include "drivers/udp_lidar_source.hpp"
#include "features/feature_config.hpp"
#include "launch/launch_file.hpp"
#include "nodes/node_config.hpp"
#include "nodes/registry.hpp"
#include "runtime/process.hpp"
#include "sim/simulator.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

namespace fs = std::filesystem;

namespace {

const fs::path kLaunch = fs::path(ADIT_SOURCE_DIR) / "launch";

// File keys, with list elements ("key.0", "key.1") folded into their list key.
std::set<std::string> fileKeys(const adit::Config& c) {
  std::set<std::string> keys;
  const std::regex element(R"(^(.*)\.\d+$)");
  for (const auto& kv : c.values()) {
    std::smatch m;
    keys.insert(std::regex_match(kv.first, m, element) ? m[1].str() : kv.first);
  }
  return keys;
}

std::vector<fs::path> yamlFiles(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".yaml") out.push_back(entry.path());
  return out;
}

}  // namespace

TEST(ConfigFiles, PipelineYamlListsEveryKeyWithItsDefault) {
  const auto defaults = adit::nodes::pipelineConfigKeys(adit::Config{});
  const auto file = adit::Config::fromYamlFile((kLaunch / "config" / "pipeline.yaml").string());
  EXPECT_NO_THROW(adit::nodes::validatePipelineConfig(file));
  const auto from_file = adit::nodes::pipelineConfigKeys(file);
  EXPECT_EQ(from_file, defaults) << "pipeline.yaml differs from the built-in defaults: run scripts/update-config.sh";
  for (const auto& key : fileKeys(file)) EXPECT_TRUE(defaults.count(key)) << "pipeline.yaml: unknown key " << key;
  for (const auto& kv : defaults) EXPECT_TRUE(fileKeys(file).count(kv.first)) << "pipeline.yaml lacks " << kv.first;
  EXPECT_GT(defaults.size(), 130u);  // all four stages and their nodes
}

// A sensor file that names a driver model gives the feature stage that model's ring count.
TEST(ConfigFiles, SensorAndVariantFilesLoad) {
  std::set<std::string> names;
  for (const fs::path& dir : {kLaunch / "sensors", kLaunch / "config"}) {
    for (const auto& path : yamlFiles(dir)) {
      names.insert(path.filename().string());
      const auto c = adit::Config::fromYamlFile(path.string());
      EXPECT_NO_THROW(adit::nodes::validatePipelineConfig(c)) << path.filename();
      EXPECT_NO_THROW(adit::nodes::makeNode("feature", c)) << path.filename();
      adit::drivers::UdpLidarConfig driver;
      EXPECT_NO_THROW(driver = adit::drivers::udpLidarConfigFrom(c)) << path.filename();
      adit::drivers::LidarStreamConfig stream;
      EXPECT_NO_THROW(stream = adit::drivers::streamConfigOf(driver)) << path.filename();
      if (c.has("lidar_driver.model")) {
        EXPECT_EQ(adit::featureConfigFrom(c).preprocess.num_rings, stream.sweep.num_beams) << path.filename();
      }
    }
  }
  for (const char* sensor : {"vlp16.yaml", "rs16.yaml", "vlp32c.yaml", "hdl32e.yaml", "hdl64.yaml", "sim.yaml"})
    EXPECT_TRUE(names.count(sensor)) << "launch/sensors/" << sensor << " is missing";
  EXPECT_GE(names.size(), 8u);
}

TEST(ConfigFiles, WorldFilesLoadInTheSimulatorAndPassThePipeline) {
  int files = 0;
  for (const auto& path : yamlFiles(kLaunch / "worlds")) {
    ++files;
    const auto c = adit::Config::fromYamlFile(path.string());
    EXPECT_NO_THROW(adit::nodes::validatePipelineConfig(c)) << path.filename();  // sim.* is not the pipeline's
    EXPECT_NO_THROW(adit::sim::simConfigFrom(c)) << path.filename();
  }
  EXPECT_GE(files, 3);
}

TEST(ConfigFiles, LaunchFilesLoad) {
  int files = 0;
  for (const auto& path : yamlFiles(kLaunch)) {
    if (path.string().find(".launch.yaml") == std::string::npos) continue;
    ++files;
    adit::launch::LaunchSpec spec;
    const std::map<std::string, std::string> vars{
        {"LOG", "run.lcmlog"}, {"RUN_DIR", "run"}, {"ADIT_ROOT", ADIT_SOURCE_DIR}, {"PRIOR_MAP", "bundle"}};
    ASSERT_NO_THROW(spec = adit::launch::loadLaunchFile(path.string(), vars)) << path.filename();
    for (const auto& process : spec.processes)  // the configuration files its processes are given load too
      for (std::size_t i = 0; i + 1 < process.command.size(); ++i)
        if (process.command[i] == "--config") {
          EXPECT_NO_THROW(adit::nodes::validatePipelineConfig(adit::Config::fromYamlFile(process.command[i + 1])))
              << path.filename() << " " << process.name << ": " << process.command[i + 1];
        }
  }
  EXPECT_GE(files, 3);
}

// `include:` and `defaults:` (the robot launch files build on live.launch.yaml): the included processes come
// first, one of the same name is replaced, defaults yield to --set, and an include cycle is an error.
// A process's --set KEY=VALUE goes over its --config files; a malformed one is an error.
TEST(ProcessOptions, SetOverridesTheConfigFiles) {
  adit::Config config = adit::Config::fromYamlString("reloc:\n  prior_map: old\n  query_distance: 0.5\n");
  adit::runtime::applyConfigSets(config, {"reloc.prior_map=new/bundle", "reloc.mode=localise"});
  EXPECT_EQ(config.values().at("reloc.prior_map"), "new/bundle");
  EXPECT_EQ(config.values().at("reloc.query_distance"), "0.5");
  EXPECT_EQ(config.values().at("reloc.mode"), "localise");
  EXPECT_THROW(adit::runtime::applyConfigSets(config, {"reloc.prior_map"}), std::runtime_error);
  EXPECT_THROW(adit::runtime::applyConfigSets(config, {"=x"}), std::runtime_error);
}

TEST(LaunchFiles, RobotFilesIncludeTheLivePipelineWithTheirSensor) {
  const std::map<std::string, std::string> vars{{"RUN_DIR", "run"}, {"ADIT_ROOT", ADIT_SOURCE_DIR}};
  const std::string dir = std::string(ADIT_SOURCE_DIR) + "/launch/";
  const auto robot = adit::launch::loadLaunchFile(dir + "robot-rs16-n100.launch.yaml", vars);
  const auto live = adit::launch::loadLaunchFile(dir + "live.launch.yaml", vars);
  EXPECT_EQ(robot.name, "robot-rs16-n100");
  EXPECT_EQ(robot.lcm_url, live.lcm_url);
  ASSERT_EQ(robot.processes.size(), live.processes.size() + 1);
  EXPECT_EQ(robot.processes.back().name, "imu-bridge");
  const auto& bridge = robot.processes[live.processes.size() - 1];
  ASSERT_EQ(bridge.name, "lidar-bridge");
  EXPECT_EQ(bridge.command[2], "rs16");
  auto with_set = vars;
  with_set["SENSOR"] = "vlp16";
  EXPECT_EQ(adit::launch::loadLaunchFile(dir + "robot-rs16-n100.launch.yaml", with_set).processes[live.processes.size() - 1].command[2],
            "vlp16");
  EXPECT_EQ(adit::launch::loadLaunchFile(dir + "robot-vlp16.launch.yaml", vars).processes.size(), live.processes.size());

  const std::string tmp = testing::TempDir();
  std::ofstream(tmp + "a.launch.yaml") << "include: b.launch.yaml\nprocesses:\n  - {name: x, command: [true]}\n";
  std::ofstream(tmp + "b.launch.yaml") << "include: a.launch.yaml\n";
  try {
    adit::launch::loadLaunchFile(tmp + "a.launch.yaml", vars);
    ADD_FAILURE() << "an include cycle was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nested"), std::string::npos) << e.what();
  }
  // localise.launch.yaml: the live pipeline plus the relocaliser, told the bundle by --set; without
  // PRIOR_MAP the file is refused rather than run without a map.
  auto with_map = vars;
  with_map["PRIOR_MAP"] = "saved/bundle";
  const auto localise = adit::launch::loadLaunchFile(dir + "localise.launch.yaml", with_map);
  ASSERT_EQ(localise.processes.size(), live.processes.size() + 1);
  const auto& command = localise.processes.back().command;
  EXPECT_EQ(command.front(), "adit-relocaliser");
  EXPECT_EQ(command.back(), "reloc.prior_map=saved/bundle");
  EXPECT_THROW(adit::launch::loadLaunchFile(dir + "localise.launch.yaml", vars), std::runtime_error);
  // extend.launch.yaml: the same, with the loop closer (in its place) and the relocaliser told to extend it.
  const auto extend = adit::launch::loadLaunchFile(dir + "extend.launch.yaml", with_map);
  ASSERT_EQ(extend.processes.size(), localise.processes.size());
  for (const auto& p : extend.processes) {
    if (p.name != "loop-closer" && p.name != "relocaliser") continue;
    ASSERT_GE(p.command.size(), 4u);
    EXPECT_EQ(p.command[p.command.size() - 3], "reloc.prior_map=saved/bundle") << p.name;
    EXPECT_EQ(p.command.back(), "reloc.mode=extend") << p.name;
  }
  EXPECT_EQ(extend.processes[3].name, "loop-closer");

  std::ofstream(tmp + "base.launch.yaml") << "name: base\nprocesses:\n  - {name: x, command: [sleep, '1']}\n  - {name: y, command: [true]}\n";
  std::ofstream(tmp + "over.launch.yaml") << "include: base.launch.yaml\nprocesses:\n  - {name: x, command: [sleep, '2']}\n";
  const auto over = adit::launch::loadLaunchFile(tmp + "over.launch.yaml", vars);
  ASSERT_EQ(over.processes.size(), 2u);
  EXPECT_EQ(over.processes[0].command[1], "2");
  EXPECT_EQ(over.name, "base");
}
