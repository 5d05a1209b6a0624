// Synthetic lidar sweeps for registration tests: a spinning multi-beam lidar ray-cast into a world of
// axis-aligned boxes (a room or corridor seen from inside, pillars and crates seen from outside), with
// LOAM-like features labelled from the known geometry: points near a box edge are corners, the rest surfaces.
#pragma once

#include "core/types.hpp"

#include <cstdint>
#include <vector>

namespace adit::test {

struct Box {
  Eigen::Vector3d min, max;
  bool inside = false;  // true: the sensor is inside (walls of a room); false: a solid obstacle
};

struct World {
  std::vector<Box> boxes;
};

struct LidarModel {
  int beams = 16;
  double min_elevation_deg = -15.0, max_elevation_deg = 15.0;
  int azimuth_steps = 1800;  // 0.2 degree
  double max_range = 60.0;
  double range_noise = 0.01;  // sigma, m
  double edge_band = 0.12;    // a hit closer than this to two faces of its box is an edge point (m)
};

// A room with pillars and crates: well-conditioned in every direction.
World boxRoom();
// A straight featureless corridor along x (4 m x 3.5 m, 2 km long): translation along x unobservable.
World featurelessCorridor();
// A straight roadway along x with a support pillar on alternating walls every `spacing` metres.
World roadwayWithPillars(double length, double spacing);
// Adds such pillars (0.4 m deep, on the walls of a 5 m wide roadway, the first at y < 0) from `from_x` up to
// `to_x`.
void addWallPillars(World& world, double from_x, double to_x, double spacing);

// One sweep from T_world_lidar, deskewed (dt = 0), features labelled; `seed` drives the range noise.
FeatureSet simulateSweep(const World& world, const Eigen::Isometry3d& T_world_lidar, const LidarModel& lidar,
                         std::int64_t utime, std::uint32_t seed);

Eigen::Isometry3d poseFrom(double x, double y, double z, double roll, double pitch, double yaw);

}  // namespace adit::test
