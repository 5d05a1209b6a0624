// The plane fit of a surface match (registration/feature_fit.hpp): a ring's arc on a curved wall is not the wall.
#include "registration/feature_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace adit {
namespace {

// Points of a roadway's round wall (radius 2 m about the x axis) where one lidar ring crosses it far ahead:
// the cross-section at x, 0.4 m apart around it (a 16-beam map's surface grid).
std::vector<Eigen::Vector3d> ringArc(double x, double first_angle, int count) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const double a = first_angle + 0.2 * i;
    points.emplace_back(x, 2.0 * std::sin(a), 2.0 * std::cos(a));
  }
  return points;
}

TEST(FitPlane, TheArcOfOneRingOnACurvedWallIsItsOwnPlaneNotTheWalls) {
  const std::vector<Eigen::Vector3d> arc = ringArc(8.0, -0.4, 5);
  // Without the check the plane through the arc is found, and it faces along the roadway: a residual that
  // holds the sweep where this ring fell, along the one direction the round wall does not observe.
  const auto plane = fitPlane(arc, 0.2);
  ASSERT_TRUE(plane);
  EXPECT_GT(std::abs(plane->normal.x()), 0.99);
  EXPECT_FALSE(fitPlane(arc, 0.2, 0.1));
}

TEST(FitPlane, TwoRingsOnTheSameWallSpanItAndGiveItsNormal) {
  std::vector<Eigen::Vector3d> patch = ringArc(8.0, -0.2, 3);
  for (const auto& p : ringArc(8.5, -0.1, 2)) patch.push_back(p);
  const auto plane = fitPlane(patch, 0.2, 0.1);
  ASSERT_TRUE(plane);
  EXPECT_LT(std::abs(plane->normal.x()), 0.05);         // across the roadway
  EXPECT_GT(std::abs(plane->normal.z()), 0.95);         // the roof's normal there (the arc is about the top)
}

TEST(FitPlane, AFlatPatchPassesAndAStepDoesNot) {
  const std::vector<Eigen::Vector3d> floor = {{0, 0, 0}, {0.4, 0, 0}, {0, 0.4, 0}, {0.4, 0.4, 0}, {0.2, 0.2, 0}};
  const auto plane = fitPlane(floor, 0.2, 0.1);
  ASSERT_TRUE(plane);
  EXPECT_NEAR(std::abs(plane->normal.z()), 1.0, 1e-9);
  std::vector<Eigen::Vector3d> step = floor;
  step.back().z() = 0.9;  // a kerb in the middle: not one plane within 0.2 m
  EXPECT_FALSE(fitPlane(step, 0.2, 0.1));
  // Points on a line leave the normal undetermined, whatever the spread asked for.
  EXPECT_FALSE(fitPlane({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}}, 0.2));
}

}  // namespace
}  // namespace adit
