// Validation of the pipeline configuration at load: unknown keys (with the nearest known key), wrong types,
// every numeric key's range from its table, and the two crashes that bad values used to cause.
#include "core/config_table.hpp"
#include "features/smoothness.hpp"
#include "mapping/voxel_map.hpp"
#include "nodes/node_config.hpp"
#include "nodes/registry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

using adit::Config;
using adit::ConfigError;

namespace {

// The ConfigError message of validating `yaml`, "" if it is valid.
std::string errorOf(const std::string& yaml) {
  try {
    adit::nodes::validatePipelineConfig(Config::fromYamlString(yaml));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string errorOf(const Config& c) {
  try {
    adit::nodes::validatePipelineConfig(c);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string text(double v) {
  std::ostringstream out;
  out.precision(17);
  out << v;
  return out.str();
}

// A config setting `key` (a list key: every element) to `value`.
Config with(const adit::ConfigKeyInfo& k, const std::string& value) {
  Config c;
  if (k.list) {
    for (int i = 0; i < 3; ++i) c.set(k.key + "." + std::to_string(i), value);
  } else {
    c.set(k.key, value);
  }
  return c;
}

}  // namespace

TEST(ConfigValidation, DefaultsAreValid) { EXPECT_EQ(errorOf(Config{}), ""); }

TEST(ConfigValidation, UnknownKeyNamesKeyFileAndNearestKey) {
  const std::string path = ::testing::TempDir() + "typo.yaml";
  {
    std::ofstream out(path);
    out << "features:\n  loam:\n    half_windw: 4\n";
  }
  const std::string e = errorOf(Config::fromYamlFile(path));
  EXPECT_NE(e.find("'features.loam.half_windw'"), std::string::npos) << e;
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'features.loam.half_window'"), std::string::npos) << e;
  EXPECT_NE(errorOf("odometry:\n  outer_iteration: 3\n").find("did you mean 'odometry.outer_iterations'"), std::string::npos);
}

TEST(ConfigValidation, SectionsOfOtherReadersPassUnknownSectionsDoNot) {
  EXPECT_EQ(errorOf("sim:\n  world: roadway-loop\nlidar_driver:\n  port: 2368\neval:\n  align: se3\n"), "");
  const std::string e = errorOf("feature:\n  loam:\n    half_window: 4\n");
  EXPECT_NE(e.find("unknown key 'feature.loam.half_window'"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'features.loam.half_window'"), std::string::npos) << e;
}

TEST(ConfigValidation, WrongTypesAreNamed) {
  const std::string e = errorOf("features:\n  loam:\n    sectors: six\n");
  EXPECT_NE(e.find("features.loam.sectors: six"), std::string::npos) << e;
  EXPECT_NE(e.find("not an integer"), std::string::npos) << e;
  EXPECT_NE(e.find(">= 1 and <= 360"), std::string::npos) << e;
  EXPECT_NE(errorOf("features:\n  loam:\n    sectors: 6.5\n").find("not an integer"), std::string::npos);
  EXPECT_NE(errorOf("features:\n  deskew:\n    enabled: maybe\n").find("not a boolean"), std::string::npos);
  EXPECT_NE(errorOf("odometry:\n  loss: l2\n").find("one of huber, cauchy, none"), std::string::npos);
  EXPECT_NE(errorOf("features:\n  loam:\n    sectors: [1, 2]\n").find("is a list"), std::string::npos);
  EXPECT_NE(errorOf("features:\n  preprocess:\n    body_box_min: 1\n").find("is not a list"), std::string::npos);
  EXPECT_NE(errorOf("features:\n  preprocess:\n    body_box_min: [1, 2]\n").find("wrong length"), std::string::npos);
  EXPECT_NE(errorOf("features:\n  ransac:\n    seed: -1\n").find("not an integer"), std::string::npos);
  EXPECT_NE(errorOf("mapping:\n  map_voxel_size_m: .nan\n").find("mapping.map_voxel_size_m"), std::string::npos);
}

// Every numeric key of every table: just outside each bound is refused with the key, the value and the
// range in the message; the bound itself (when closed) and the default are accepted.
TEST(ConfigValidation, EveryNumericRangeIsEnforced) {
  int bounds = 0;
  for (const auto& k : adit::nodes::pipelineConfigDescription(Config{})) {
    if (!k.numeric) continue;
    const double step = k.integer ? 1.0 : 1e-3;
    const auto expectRefused = [&](double v) {
      const std::string e = errorOf(with(k, text(v)));
      EXPECT_NE(e.find(k.key), std::string::npos) << k.key << " = " << v << " was accepted";
      EXPECT_NE(e.find(k.range.text()), std::string::npos) << e;
      ++bounds;
    };
    if (std::isfinite(k.range.lo)) {
      expectRefused(k.range.lo_open ? k.range.lo : k.range.lo - std::max(step, std::fabs(k.range.lo) * 1e-3));
      if (!k.range.lo_open) {
        EXPECT_EQ(errorOf(with(k, text(k.range.lo))), "") << k.key << " at its lower bound";
      }
    }
    if (std::isfinite(k.range.hi)) {
      expectRefused(k.range.hi_open ? k.range.hi : k.range.hi + std::max(step, std::fabs(k.range.hi) * 1e-3));
      if (!k.range.hi_open) {
        EXPECT_EQ(errorOf(with(k, text(k.range.hi))), "") << k.key << " at its upper bound";
      }
    }
  }
  EXPECT_GT(bounds, 150);
}

TEST(ConfigValidation, FormerCrashesAreRefusedAtLoad) {
  EXPECT_NE(errorOf("features:\n  loam:\n    half_window: -1\n").find("features.loam.half_window: -1"), std::string::npos);
  EXPECT_NE(errorOf("mapping:\n  map_voxel_size_m: 1e-12\n").find("out of range"), std::string::npos);
  EXPECT_THROW(adit::nodes::makeNode("feature", Config::fromYamlString("features:\n  loam:\n    half_window: -1\n")),
               ConfigError);
}

// The same values given to the stages directly (bypassing the configuration) are handled, not crashes.
TEST(ConfigValidation, StagesSurviveTheFormerCrashValues) {
  adit::features::RingCloud cloud;
  for (int i = 0; i < 200; ++i) {
    const float a = static_cast<float>(i) * 0.01f;
    cloud.points.push_back({Eigen::Vector3f(5 * std::cos(a), 5 * std::sin(a), 0), 0.0f, 0, 0.0f});
  }
  cloud.ring_begin = {0, 200};
  adit::LoamConfig loam;
  for (int w : {-1, 0, 100000, 2147483647}) {
    loam.half_window = w;
    const auto s = adit::features::scorePoints(cloud, loam);
    for (std::size_t i = 0; i < s.usable.size(); ++i) EXPECT_EQ(s.usable[i], 0) << "no complete window, w=" << w;
  }
  const adit::VoxelKey far = adit::voxelOf(Eigen::Vector3d(1e3, -1e3, 0.5), 1e-12);
  EXPECT_EQ(far.x, 2147483646);
  EXPECT_EQ(far.y, -2147483646);
  adit::VoxelMap map(1e-12, 0.0, 20);
  map.insert({Eigen::Vector3d(1e3, 2e3, 3e3), Eigen::Vector3d(1e3, 2e3, 3e3 + 1)});
  EXPECT_EQ(map.numPoints(), 2u);
  EXPECT_EQ(map.nearest(Eigen::Vector3d(1e3, 2e3, 3e3), 1, 0.5).size(), 1u);
}

TEST(ConfigValidation, TableDefaultsAreTheStructDefaultsAndDocumented) {
  for (const auto& k : adit::nodes::pipelineConfigDescription(Config{})) {
    EXPECT_EQ(k.value, k.default_value) << k.key;
    EXPECT_FALSE(k.doc.empty()) << k.key;
    if (k.numeric && !k.list) {
      EXPECT_EQ(errorOf(with(k, k.default_value)), "") << k.key << ": default outside its range";
    }
  }
}

// The bus input checks come from section `input`, for every node the registry builds (how the checks act on
// messages is tested in tests/runtime); without the section every node has the built-in limits.
TEST(ConfigValidation, InputLimitsAreConfiguredForEveryNode) {
  const Config tight = Config::fromYamlString(
      "input:\n  max_angular_velocity: 5.0\n  max_future_s: 0.5\n  max_text_length: 100\n  max_elements: 1000\n");
  for (const std::string& name : adit::nodes::pipelineNodeNames()) {
    const auto node = adit::nodes::makeNode(name, tight);
    EXPECT_DOUBLE_EQ(node->inputChecks().values.max_angular_velocity, 5.0) << name;
    EXPECT_DOUBLE_EQ(node->inputChecks().max_future_s, 0.5) << name;
    EXPECT_EQ(node->inputChecks().values.max_string_length, 100u) << name;
    EXPECT_EQ(node->inputChecks().wire.max_elements, 1000) << name;
    const auto standard = adit::nodes::makeNode(name, Config{});
    EXPECT_DOUBLE_EQ(standard->inputChecks().values.max_angular_velocity, adit::msg::InputLimits{}.max_angular_velocity);
    EXPECT_EQ(standard->inputChecks().max_seq_gap, adit::runtime::InputChecks{}.max_seq_gap);
  }
  EXPECT_NE(errorOf("input:\n  max_future_s: 0\n"), "");
  EXPECT_NE(errorOf("input:\n  confirm_messages: 0\n"), "");
  EXPECT_NE(errorOf("input:\n  max_angular_veloctiy: 5\n"), "");  // misspelt: unknown key
}
