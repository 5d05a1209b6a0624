// The map-against-world figure: distances to the surface the samples describe, not to the samples.
#include "eval/map_accuracy.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>

namespace adit::eval {
namespace {

// A floor (z = 0) and a wall (x = 5), sampled every 0.1 m.
std::vector<Eigen::Vector3d> floorAndWall() {
  std::vector<Eigen::Vector3d> s;
  for (int i = 0; i <= 50; ++i)
    for (int j = 0; j <= 50; ++j) {
      s.emplace_back(0.1 * i, 0.1 * j, 0.0);
      s.emplace_back(5.0, 0.1 * i, 0.1 * j);
    }
  return s;
}

TEST(MapAccuracy, DistancesAreToTheSurfaceNotToItsSamples) {
  // Map points 3 cm above the floor, between the samples (the nearest sample is 7.7 cm away).
  std::vector<Eigen::Vector3d> map;
  for (int i = 5; i < 40; ++i)
    for (int j = 5; j < 40; ++j) map.emplace_back(0.1 * i + 0.05, 0.1 * j + 0.05, 0.03);
  const MapAccuracy a = mapAgainstWorld(map, floorAndWall(), Similarity{});
  ASSERT_TRUE(a.valid);
  EXPECT_EQ(a.points, map.size());
  EXPECT_NEAR(a.mean_m, 0.03, 1e-9);
  EXPECT_NEAR(a.p95_m, 0.03, 1e-9);
  EXPECT_EQ(a.beyond_02_m, 0.0);
}

TEST(MapAccuracy, TheMapIsPlacedByTheAlignmentAndGhostsShowBeyond20cm) {
  std::vector<Eigen::Vector3d> map;
  for (int i = 0; i < 95; ++i) map.emplace_back(1.0 + 0.03 * i, 2.0, 0.0);  // on the floor...
  for (int i = 0; i < 5; ++i) map.emplace_back(1.0 + 0.1 * i, 2.0, 0.5);    // ...and a ghost 0.5 m above it
  // The map's frame is the world's shifted 1 m up and turned 90 deg about z: the alignment undoes it.
  Similarity to_world;
  to_world.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  to_world.translation = Eigen::Vector3d(4.0, 0.0, 1.0);
  std::vector<Eigen::Vector3d> in_map_frame;
  for (const Eigen::Vector3d& p : map) in_map_frame.push_back(to_world.rotation.transpose() * (p - to_world.translation));
  const MapAccuracy a = mapAgainstWorld(in_map_frame, floorAndWall(), to_world);
  ASSERT_TRUE(a.valid);
  EXPECT_NEAR(a.beyond_02_m, 0.05, 1e-12);
  EXPECT_NEAR(a.mean_m, 0.05 * 0.5, 1e-6);
  EXPECT_LT(a.p95_m, 1e-6);
  // Without the alignment the same points are far from every surface.
  EXPECT_GT(mapAgainstWorld(in_map_frame, floorAndWall(), Similarity{}).beyond_02_m, 0.5);
}

TEST(MapAccuracy, NothingToCompareIsNotValid) {
  EXPECT_FALSE(mapAgainstWorld({}, floorAndWall(), Similarity{}).valid);
  EXPECT_FALSE(mapAgainstWorld({Eigen::Vector3d::Zero()}, {}, Similarity{}).valid);
}

}  // namespace
}  // namespace adit::eval
