// Test helper: a world of solid axis-aligned boxes (rock, pillars, niches) and a 16-beam lidar ray-caster,
// enough to make roadway-like sweeps with known ground truth for the loop-closure tests.
#pragma once

#include "core/types.hpp"

#include <cstdint>
#include <vector>

namespace adit::testing {

struct Box {
  Eigen::Vector3d lo, hi;
};

struct BoxWorld {
  std::vector<Box> boxes;
  void add(double x0, double y0, double z0, double x1, double y1, double z1) {
    boxes.push_back({Eigen::Vector3d(x0, y0, z0), Eigen::Vector3d(x1, y1, z1)});
  }
  // Floor slab below z = 0 and roof slab above z = height over [x0, x1] x [y0, y1].
  void addFloorAndRoof(double x0, double y0, double x1, double y1, double height);
};

// VLP-16-like sweep from T_world_lidar: 16 beams -15..+15 deg, `azimuth_steps` per turn, Gaussian range noise.
LidarScan simulateSweep(const BoxWorld& world, const Eigen::Isometry3d& T_world_lidar, std::uint32_t seed,
                        int azimuth_steps = 900, double range_noise = 0.01, double max_range = 80.0);

std::vector<Eigen::Vector3f> positions(const LidarScan& scan);

Eigen::Isometry3d poseXYYaw(double x, double y, double z, double yaw);

}  // namespace adit::testing

namespace adit::testing {

// A straight roadway along x over [x0, x1], `width` wide, 4 m high, with `features` boxes sticking out of the
// walls (equipment, timber, ribs) at positions drawn from `seed`, and optionally a cross-cut opening at x = 0.
BoxWorld makeRoadway(std::uint32_t seed, double width = 4.8, int features = 8, bool cross_cut = false,
                     double x0 = -60.0, double x1 = 60.0);

// A straight roadway along x from -200 to 300 m, 2 * half_width wide and 4 m high, whose equipment (`boxes`
// boxes against alternate walls, drawn from `seed`) repeats exactly every `period` metres, for the periods
// first..last: a place one period on looks identical (aliasing).
BoxWorld makePeriodicRoadway(std::uint32_t seed, double period, int boxes, double half_width, int first, int last);

}  // namespace adit::testing
