// The configuration files under launch/ against the code: launch/config/pipeline.yaml lists exactly the
// keys the stages read, each with its built-in default, and every other file names only real keys (a typo
// in a key would otherwise be ignored silently and the default used).
#include "core/config.hpp"
#include "drivers/udp_lidar_source.hpp"
#include "nodes/registry.hpp"

#include <gtest/gtest.h>

#include <filesystem>
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

std::map<std::string, std::string> driverKeys(const adit::Config& c) {
  std::map<std::string, std::string> reads;
  c.recordReadsInto(&reads);
  adit::drivers::udpLidarConfigFrom(c);
  c.recordReadsInto(nullptr);
  return reads;
}

}  // namespace

TEST(ConfigFiles, PipelineYamlListsEveryKeyWithItsDefault) {
  const auto defaults = adit::nodes::pipelineConfigKeys(adit::Config{});
  const auto file = adit::Config::fromYamlFile((kLaunch / "config" / "pipeline.yaml").string());
  const auto from_file = adit::nodes::pipelineConfigKeys(file);
  EXPECT_EQ(from_file, defaults) << "pipeline.yaml differs from the built-in defaults: regenerate it with `adit config`";
  for (const auto& key : fileKeys(file)) EXPECT_TRUE(defaults.count(key)) << "pipeline.yaml: unknown key " << key;
  for (const auto& kv : defaults) EXPECT_TRUE(fileKeys(file).count(kv.first)) << "pipeline.yaml lacks " << kv.first;
  EXPECT_GT(defaults.size(), 100u);  // all four stages were asked
}

TEST(ConfigFiles, SensorAndVariantFilesNameOnlyRealKeys) {
  const auto pipeline_keys = adit::nodes::pipelineConfigKeys(adit::Config{});
  const auto driver = driverKeys(adit::Config{});
  int files = 0;
  for (const fs::path& dir : {kLaunch / "sensors", kLaunch / "config"}) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() != ".yaml") continue;
      ++files;
      const auto c = adit::Config::fromYamlFile(entry.path().string());
      for (const auto& key : fileKeys(c))
        EXPECT_TRUE(pipeline_keys.count(key) || driver.count(key)) << entry.path().filename() << ": unknown key " << key;
      EXPECT_NO_THROW(adit::nodes::pipelineConfigKeys(c)) << entry.path().filename() << ": a value does not parse";
    }
  }
  EXPECT_GE(files, 5);
}

TEST(ConfigFiles, AUnknownKeyIsCaughtByTheCheck) {
  // The check above can fail: a misspelt key is not among the keys the stages read.
  const auto keys = adit::nodes::pipelineConfigKeys(adit::Config{});
  EXPECT_FALSE(keys.count("features.preprocess.min_rnage"));
  EXPECT_TRUE(keys.count("features.preprocess.min_range"));
}
