// Ray casting: analytic hits on each primitive, BVH == brute force, local crop == whole scene.
#include "sim/rng.hpp"
#include "sim/scene.hpp"
#include "sim/world.hpp"

#include <gtest/gtest.h>

namespace adit::sim {
namespace {

Ray makeRay(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max = 1e3f) {
  Ray r;
  r.origin = origin;
  r.dir = dir.normalized();
  r.t_max = t_max;
  return r;
}

TEST(Scene, AnalyticHitsOnEachPrimitive) {
  Scene scene;
  scene.addQuad({5, -1, -1}, {5, 1, -1}, {5, 1, 1}, {5, -1, 1}, 0.3f);                       // wall at x = 5
  scene.addBox({0, 5, 0}, Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitZ()).toRotationMatrix(), {1, 1, 1}, 0.5f);
  scene.addCylinder({0, -5, -1}, {0, -5, 1}, 0.5f, 0.7f);                                        // vertical, r 0.5
  scene.build();
  Hit h = scene.intersect(makeRay({0, 0, 0}, {1, 0, 0}));
  ASSERT_TRUE(h.valid());
  EXPECT_NEAR(h.t, 5.0f, 1e-5f);
  EXPECT_NEAR(std::fabs(h.normal.x()), 1.0f, 1e-6f);
  EXPECT_FLOAT_EQ(h.reflectivity, 0.3f);
  // Rotated box: the face normal is the box's local -y axis turned by 0.3 rad; distance along +y analytic.
  h = scene.intersect(makeRay({0, 0, 0}, {0, 1, 0}));
  ASSERT_TRUE(h.valid());
  const float half_width_along_y = 1.0f / std::cos(0.3f);  // face crossing of the centre line
  EXPECT_NEAR(h.t, 5.0f - half_width_along_y, 1e-4f);
  h = scene.intersect(makeRay({0, 0, 0}, {0, -1, 0}));
  ASSERT_TRUE(h.valid());
  EXPECT_NEAR(h.t, 4.5f, 1e-5f);
  EXPECT_NEAR(h.normal.y(), 1.0f, 1e-5f);
  // Cylinder cap from above.
  h = scene.intersect(makeRay({0, -5, 3}, {0, 0, -1}));
  ASSERT_TRUE(h.valid());
  EXPECT_NEAR(h.t, 2.0f, 1e-5f);
  // Misses and range limit.
  EXPECT_FALSE(scene.intersect(makeRay({0, 0, 0}, {0, 0, 1})).valid());
  EXPECT_FALSE(scene.intersect(makeRay({0, 0, 0}, {1, 0, 0}, 4.9f)).valid());
}

TEST(Scene, EmptySceneAndDegeneratePrimitivesNeverHit) {
  Scene scene;
  scene.addTriangle({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, 0.5f);  // collinear
  scene.addCylinder({0, 0, 0}, {0, 0, 0}, 1.0f, 0.5f);       // zero length
  scene.addBox({0, 0, 0}, Eigen::Matrix3f::Identity(), {0, 1, 1}, 0.5f);
  scene.build();
  EXPECT_EQ(scene.size(), 0u);
  EXPECT_FALSE(scene.intersect(makeRay({-5, 0, 0}, {1, 0, 0})).valid());
}

TEST(Scene, BvhMatchesBruteForceOnRandomScene) {
  Rng rng(7);
  Scene scene;
  auto rnd = [&](double s) {
    return Eigen::Vector3f(rng.uniform(-s, s), rng.uniform(-s, s), rng.uniform(-s, s));
  };
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3f c = rnd(30.0);
    scene.addTriangle(c, Eigen::Vector3f(c + rnd(1.0)), Eigen::Vector3f(c + rnd(1.0)), 0.2f);
  }
  for (int i = 0; i < 300; ++i) {
    const Eigen::Matrix3f R = Eigen::Quaternionf(rng.normal(), rng.normal(), rng.normal(), rng.normal()).normalized().toRotationMatrix();
    scene.addBox(rnd(30.0), R, Eigen::Vector3f(rnd(0.5).cwiseAbs() + Eigen::Vector3f::Constant(0.05f)), 0.4f);
  }
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3f a = rnd(30.0);
    scene.addCylinder(a, Eigen::Vector3f(a + rnd(2.0)), static_cast<float>(rng.uniform(0.02, 0.3)), 0.6f);
  }
  scene.build();
  int hits = 0;
  for (int i = 0; i < 6000; ++i) {
    const Ray ray = makeRay(rnd(35.0), rnd(1.0), 80.0f);
    const Hit fast = scene.intersect(ray), slow = scene.intersectBruteForce(ray);
    ASSERT_EQ(fast.valid(), slow.valid()) << "ray " << i;
    if (!fast.valid()) continue;
    ++hits;
    EXPECT_EQ(fast.t, slow.t) << "ray " << i;  // same primitive test: bit-identical distance
  }
  EXPECT_GT(hits, 300);  // the comparison is not vacuous
}

TEST(Scene, LocalCropAnswersLikeTheWholeScene) {
  WorldConfig config = worldConfigFor("roadway-loop", 3);
  const World world = buildWorld(config);
  LocalRayCaster caster(world.scene);
  Rng rng(11);
  int compared = 0, far = 0;
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (int i = 0; i < 20000; ++i) {
    if (i % 400 == 0) {  // a new place every 400 rays (each move rebuilds the crop)
      centre = Eigen::Vector3f(static_cast<float>(rng.uniform(5.0, 160.0)), 0.0f, 1.0f);
      caster.moveTo(centre);
    }
    const Eigen::Vector3f origin = centre + Eigen::Vector3f(static_cast<float>(rng.uniform(-0.5, 0.5)),
                                                            static_cast<float>(rng.uniform(-1.0, 1.0)),
                                                            static_cast<float>(rng.uniform(-0.4, 0.6)));
    const Ray ray = makeRay(origin, Eigen::Vector3f(rng.normal(), rng.normal(), 0.3 * rng.normal()), 100.0f);
    const Hit a = world.scene.intersect(ray), b = caster.intersect(ray);
    ASSERT_EQ(a.valid(), b.valid());
    if (!a.valid()) continue;
    ++compared;
    far += a.t > 10.0f;
    EXPECT_NEAR(a.t, b.t, 1e-5f);
  }
  EXPECT_GT(compared, 18000);
  EXPECT_GT(far, 500);  // rays leaving the crop took the fallback path
}

}  // namespace
}  // namespace adit::sim
