// Worlds: sizes the issue asks for, determinism, and a robot route that stays in free space on the floor.
#include "sim/motion.hpp"
#include "sim/world.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace adit::sim {
namespace {

// Smallest distance from p to any surface, probed by 64 rays around a sphere.
float clearance(const Scene& scene, const Eigen::Vector3d& p) {
  float best = 1e9f;
  for (int i = 0; i < 64; ++i) {
    const double z = -1.0 + (2.0 * i + 1.0) / 64.0, phi = i * 2.399963229728653;  // Fibonacci sphere
    const double r = std::sqrt(1.0 - z * z);
    Ray ray;
    ray.origin = p.cast<float>();
    ray.dir = Eigen::Vector3f(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
    ray.t_max = 50.0f;
    const Hit h = scene.intersect(ray);
    if (h.valid()) best = std::min(best, h.t);
  }
  return best;
}

class EveryWorld : public ::testing::TestWithParam<const char*> {};

TEST_P(EveryWorld, RobotDrivesInFreeSpaceOnTheFloor) {
  const World world = buildWorld(worldConfigFor(GetParam(), 1));
  const MotionConfig motion;
  const PlannedMotion plan = planMotion(world, motion, 200.0, 1);
  int samples = 0;
  for (double t = 0.0; t <= 200.0; t += 0.7, ++samples) {
    const Eigen::Isometry3d T = plan.trajectory.pose(t);
    // The lidar is mount_height above the floor under it (floor relief, tilt and bounce: +-10 cm).
    Ray down;
    down.origin = T.translation().cast<float>();
    down.dir = -Eigen::Vector3f::UnitZ();
    const Hit floor = world.scene.intersect(down);
    ASSERT_TRUE(floor.valid()) << GetParam() << " t=" << t;
    EXPECT_NEAR(floor.t, motion.mount_height, 0.1) << GetParam() << " t=" << t;
    // Nothing within 0.6 m of the lidar: no driving through walls, furniture or pillars.
    EXPECT_GT(clearance(world.scene, T.translation()), 0.6f) << GetParam() << " t=" << t << " at "
                                                             << T.translation().transpose();
    // Upright within the floor's slopes (grade < 2.5 deg, relief and vibration a few deg).
    EXPECT_GT(T.linear()(2, 2), std::cos(8.0 * M_PI / 180.0)) << GetParam() << " t=" << t;
  }
  EXPECT_GT(samples, 250);
}

INSTANTIATE_TEST_SUITE_P(Sim, EveryWorld,
                         ::testing::Values("roadway-straight", "roadway-loop", "room-and-pillar", "featureless"));

TEST(World, SizesAsSpecified) {
  const World straight = buildWorld(worldConfigFor("roadway-straight"));
  EXPECT_GE(straight.routeLength(), 300.0);
  const World loop = buildWorld(worldConfigFor("roadway-loop"));
  EXPECT_TRUE(loop.route_closed);
  EXPECT_GE(loop.routeLength(), 500.0);
  EXPECT_GE(loop.network.edges.size(), 9u);  // perimeter pieces + cross-cuts (+ stubs)
  const World rp = buildWorld(worldConfigFor("room-and-pillar"));
  int four_way = 0;
  for (int n = 0; n < static_cast<int>(rp.network.nodes.size()); ++n) {
    int degree = 0;
    for (const auto& e : rp.network.edges) degree += (e.first == n) + (e.second == n);
    four_way += degree == 4;
  }
  EXPECT_GE(four_way, 16);  // many identical intersections
  const World featureless = buildWorld(worldConfigFor("featureless"));
  EXPECT_GE(featureless.routeLength(), 300.0);
  EXPECT_TRUE(featureless.scene.boxes().empty() && featureless.scene.cylinders().empty());  // no furniture
  EXPECT_GT(straight.scene.boxes().size(), 1000u);  // arches, bolt plates, brackets, equipment
  EXPECT_GT(straight.scene.cylinders().size(), 1000u);  // bolt tails, pipes, cables
  EXPECT_THROW(buildWorld(worldConfigFor("moon")), std::invalid_argument);
}

TEST(World, SameSeedSameWorldOtherSeedOtherFurniture) {
  const World a = buildWorld(worldConfigFor("roadway-straight", 4));
  const World b = buildWorld(worldConfigFor("roadway-straight", 4));
  const World c = buildWorld(worldConfigFor("roadway-straight", 5));
  ASSERT_EQ(a.scene.size(), b.scene.size());
  ASSERT_EQ(a.scene.triangles().size(), b.scene.triangles().size());
  for (std::size_t i = 0; i < a.scene.triangles().size(); ++i)
    ASSERT_EQ(a.scene.triangles()[i].a, b.scene.triangles()[i].a);
  for (std::size_t i = 0; i < a.scene.boxes().size(); ++i) ASSERT_EQ(a.scene.boxes()[i].center, b.scene.boxes()[i].center);
  bool differs = a.scene.boxes().size() != c.scene.boxes().size();
  for (std::size_t i = 0; !differs && i < a.scene.boxes().size(); ++i)
    differs = a.scene.boxes()[i].center != c.scene.boxes()[i].center;
  EXPECT_TRUE(differs);
}

TEST(World, ConfigKeysOverrideDefaults) {
  adit::Config cfg;
  cfg.set("sim.roadway.width", "5.5");
  cfg.set("sim.roadway.roof_bolts", "false");
  const WorldConfig c = worldConfigFrom(cfg, "roadway-straight", 3);
  EXPECT_DOUBLE_EQ(c.width, 5.5);
  EXPECT_FALSE(c.roof_bolts);
  EXPECT_TRUE(c.support_arches);
  EXPECT_EQ(c.seed, 3u);
}

}  // namespace
}  // namespace adit::sim
