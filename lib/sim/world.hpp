// Procedural underground worlds: a network of straight roadways (edges) meeting at junctions (nodes), turned into
// ray-castable geometry with the things real coal-mine roadways have, plus the route the robot drives.
//
// Built-in worlds (name -> layout, all sizes overridable in WorldConfig):
//   roadway-straight  one 320 m roadway, arched roof, bolts, steel arches, pipes, cables, niches, equipment.
//   roadway-loop      a 175 m x 80 m rectangle of roadways (510 m perimeter) with 2 cross-cuts and dead-end stubs;
//                     the robot drives the perimeter counter-clockwise, lap after lap (a real revisit for loop
//                     closure). See simulator.hpp for the duration needed to drive 1.2 laps.
//   room-and-pillar   a 6 x 6 grid of junctions between 15 m square pillars: many identical intersections
//                     (perceptual aliasing); the robot does a seeded random walk through it.
//   featureless       a 320 m smooth arched tunnel, no furniture: scan matching is degenerate along the axis
//                     wherever both end walls are beyond the lidar's 100 m (x in ~100..220 m).
//
// Frame: world z up, x east; the floor's mean height is z = 0 plus the slow grade. Everything derives from the
// seed; the same WorldConfig gives the same world bit for bit.
#pragma once

#include "core/config.hpp"
#include "sim/scene.hpp"
#include "sim/wave_field.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace adit::sim {

struct WorldConfig {
  std::string name = "roadway-loop";  // roadway-straight | roadway-loop | room-and-pillar | featureless
  std::uint64_t seed = 1;             // drives furniture placement, relief and the room-and-pillar route

  // Cross-section (typical coal-mine roadway: 4-5 m wide, 3 m high).
  double width = 4.5;        // wall to wall (m)
  double wall_height = 2.4;  // height of the vertical side walls above the floor (m)
  double roof_rise = 0.6;    // arch rise above the wall tops (m); 0 = flat roof (rectangular section)

  // Relief (RMS, m). Floor relief also makes the robot pitch and roll.
  double floor_roughness = 0.03;  // wavelengths 1.5-12 m: rutted, uneven floor (robot pitch/roll of a few deg)
  double wall_roughness = 0.03;   // wavelengths 1.5-6 m on walls and roof: cut coal, spalling
  double grade_amplitude = 1.0;   // slow up/down of the whole roadway, wavelengths 150-400 m (slopes < ~2 deg)

  // Furniture: what gives a 16-beam lidar its only features in a roadway.
  bool support_arches = true;  // steel sets following the section
  double arch_spacing = 2.0;   // m between support arches (+-0.15 m jitter)
  bool roof_bolts = true;      // bolt plates + tails on the roof
  double bolt_spacing = 1.0;   // m between bolt rows, 5 bolts a row
  bool services = true;        // pipes on the left wall, sagging cables on the right wall
  bool equipment = true;       // boxes on the floor against a wall every ~40 m
  bool side_cuts = true;       // niches cut into a wall every ~70 m

  // Layout sizes.
  double straight_length = 320.0;  // roadway-straight and featureless (m)
  double loop_size_x = 175.0;      // roadway-loop rectangle (m): perimeter 2 * (x + y) = 510 m, 507 m driven
  double loop_size_y = 80.0;
  int loop_crosscuts = 2;       // north-south roadways across the loop
  int pillar_grid = 6;          // room-and-pillar: junctions per side
  double pillar_size = 15.0;    // room-and-pillar: pillar side (m)
  double route_length = 6000.0; // room-and-pillar: length of the random walk (m), longer than any run needs
};

// Defaults of a built-in world (throws std::invalid_argument for an unknown name).
WorldConfig worldConfigFor(const std::string& name, std::uint64_t seed = 1);
// Defaults for `name`, overridden by keys "sim.roadway.<field>" (e.g. sim.roadway.width, sim.roadway.furniture
// flags by their field names: sim.roadway.roof_bolts ...).
WorldConfig worldConfigFrom(const adit::Config& c, const std::string& name, std::uint64_t seed);

// Junctions and straight roadways between them; every edge is parallel to the x or y axis.
struct RoadNetwork {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::pair<int, int>> edges;
};

struct World {
  WorldConfig config;
  RoadNetwork network;
  Scene scene;           // built (BVH ready)
  WaveField floor_relief;  // floor unevenness (m)
  WaveField grade;         // slow vertical profile (m)
  WaveField wall_relief;   // 3D relief of walls and roof (m)

  // Route: waypoints of a polyline along roadway centre lines. If closed, the last equals the first and the
  // robot repeats it lap after lap; otherwise it stops at the end.
  std::vector<Eigen::Vector2d> route;
  bool route_closed = false;

  // Height of the ground (floor surface) at (x, y).
  double groundHeight(double x, double y) const { return grade.value(x, y) + floor_relief.value(x, y); }
  // Length of one pass of the route polyline (m), corners not rounded.
  double routeLength() const;
};

// Builds a world (geometry, BVH, route). Throws std::invalid_argument for an unknown name or invalid sizes.
World buildWorld(const WorldConfig& config);

}  // namespace adit::sim
