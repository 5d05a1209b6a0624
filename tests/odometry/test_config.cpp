// Config keys reach the stage configs; "ablation.aloam" switches the defaults to plain A-LOAM behaviour.
#include "mapping/scan_to_map.hpp"
#include "odometry/scan_to_scan.hpp"

#include <gtest/gtest.h>

namespace adit {
namespace {

TEST(OdometryConfig, DefaultsWhenKeysAreMissing) {
  const ScanToScanConfig s = scanToScanConfigFrom(Config{});
  EXPECT_EQ(s.outer_iterations, ScanToScanConfig{}.outer_iterations);
  EXPECT_TRUE(s.use_link3d_seed);
  EXPECT_TRUE(s.registration.degeneracy_prior);
  const MapperConfig m = mapperConfigFrom(Config{});
  EXPECT_DOUBLE_EQ(m.local_map_radius_m, MapperConfig{}.local_map_radius_m);
  EXPECT_TRUE(m.registration.degeneracy_prior);
}

TEST(OdometryConfig, KeysAreRead) {
  const Config c = Config::fromYamlString(
      "odometry:\n  outer_iterations: 5\n  max_match_distance_m: 2.5\n  loss: cauchy\n"
      "  degeneracy_ratio_translation: 0.05\n  use_link3d_seed: false\n  degeneracy_remap: false\n"
      "  hold_velocity_time_constant_s: 2.5\n"
      "mapping:\n  local_map_radius_m: 40\n  surf_resolution_m: 0.8\n  degeneracy_prior: false\n");
  const ScanToScanConfig s = scanToScanConfigFrom(c);
  EXPECT_EQ(s.outer_iterations, 5);
  EXPECT_DOUBLE_EQ(s.max_match_distance_m, 2.5);
  EXPECT_EQ(s.registration.loss, "cauchy");
  EXPECT_DOUBLE_EQ(s.registration.degeneracy_ratio_translation, 0.05);
  EXPECT_FALSE(s.use_link3d_seed);
  EXPECT_FALSE(s.registration.degeneracy_remap);
  EXPECT_DOUBLE_EQ(s.hold_velocity_time_constant_s, 2.5);
  const MapperConfig m = mapperConfigFrom(c);
  EXPECT_DOUBLE_EQ(m.local_map_radius_m, 40.0);
  EXPECT_DOUBLE_EQ(m.surf_resolution_m, 0.8);
  EXPECT_FALSE(m.registration.degeneracy_prior);
  EXPECT_THROW(scanToScanConfigFrom(Config::fromYamlString("odometry:\n  outer_iterations: lots\n")),
               std::runtime_error);
}

TEST(OdometryConfig, AloamAblationSwitchesDefaultsButKeysStillOverride) {
  const ScanToScanConfig s = scanToScanConfigFrom(Config::fromYamlString("ablation:\n  aloam: true\n"));
  EXPECT_FALSE(s.use_link3d_seed);
  EXPECT_FALSE(s.registration.degeneracy_prior);
  EXPECT_TRUE(s.three_point_planes);
  EXPECT_EQ(s.line_min_rings, 2);
  EXPECT_FALSE(mapperConfigFrom(Config::fromYamlString("ablation:\n  aloam: true\n")).registration.degeneracy_prior);
  const ScanToScanConfig o =
      scanToScanConfigFrom(Config::fromYamlString("ablation:\n  aloam: true\nodometry:\n  outer_iterations: 3\n"));
  EXPECT_EQ(o.outer_iterations, 3);
  EXPECT_FALSE(o.use_link3d_seed);
}

}  // namespace
}  // namespace adit
