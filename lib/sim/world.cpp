#include "sim/world.hpp"

#include "sim/roadway_builder.hpp"

#include <cmath>
#include <stdexcept>

namespace adit::sim {
namespace {

// roadway-straight / featureless: one roadway between two dead ends, driven from one end to the other.
void layoutStraight(World& w) {
  const double length = w.config.straight_length;
  w.network.nodes = {{0.0, 0.0}, {length, 0.0}};
  w.network.edges = {{0, 1}};
  w.route = {{2.0, 0.0}, {length - 4.0, 0.0}};
  w.route_closed = false;
}

// roadway-loop: rectangle with north-south cross-cuts and a few dead-end stubs; route = perimeter, CCW.
void layoutLoop(World& w, Rng& rng) {
  const double sx = w.config.loop_size_x, sy = w.config.loop_size_y;
  const int n = std::max(0, w.config.loop_crosscuts);
  auto& nodes = w.network.nodes;
  auto& edges = w.network.edges;
  // South row west->east, then north row west->east.
  for (int row = 0; row < 2; ++row)
    for (int i = 0; i <= n + 1; ++i) nodes.emplace_back(sx * i / (n + 1), row * sy);
  const int south = 0, north = n + 2;
  for (int i = 0; i <= n; ++i) {
    edges.emplace_back(south + i, south + i + 1);
    edges.emplace_back(north + i, north + i + 1);
  }
  for (int i = 0; i <= n + 1; ++i) edges.emplace_back(south + i, north + i);  // sides and cross-cuts
  // Dead-end stubs continuing some roadways outwards (real districts branch everywhere).
  const Eigen::Vector2d outward[4] = {{-1, 0}, {1, 0}, {-1, 0}, {1, 0}};
  const int corner[4] = {south, south + n + 1, north, north + n + 1};
  for (int k = 0; k < 4; ++k) {
    if (rng.uniform() < 0.5) continue;
    nodes.push_back(nodes[corner[k]] + outward[k] * rng.uniform(12.0, 25.0));
    edges.emplace_back(corner[k], static_cast<int>(nodes.size()) - 1);
  }
  const double start = std::min(20.0, sx / 4);
  w.route = {{start, 0.0}, {sx, 0.0}, {sx, sy}, {0.0, sy}, {0.0, 0.0}, {start, 0.0}};
  w.route_closed = true;
}

// room-and-pillar: grid of junctions; route = seeded random walk (no U-turns, prefers going straight).
void layoutRoomAndPillar(World& w, Rng& rng) {
  const int n = std::max(2, w.config.pillar_grid);
  const double pitch = w.config.pillar_size + w.config.width;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) w.network.nodes.emplace_back(i * pitch, j * pitch);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (i + 1 < n) w.network.edges.emplace_back(j * n + i, j * n + i + 1);
      if (j + 1 < n) w.network.edges.emplace_back(j * n + i, (j + 1) * n + i);
    }
  int i = 0, j = 0, di = 1, dj = 0;
  w.route = {{3.0, 0.0}};
  double length = 0.0;
  while (length < w.config.route_length) {
    const int options[3][2] = {{di, dj}, {-dj, di}, {dj, -di}};  // straight, left, right
    const double weights[3] = {2.0, 1.0, 1.0};
    int choice = -1;
    for (int attempt = 0; attempt < 16 && choice < 0; ++attempt) {
      const double r = rng.uniform(0.0, 4.0);
      const int c = r < weights[0] ? 0 : (r < weights[0] + weights[1] ? 1 : 2);
      const int ni = i + options[c][0], nj = j + options[c][1];
      if (ni >= 0 && ni < n && nj >= 0 && nj < n) choice = c;
    }
    if (choice < 0) {  // corner reached going outwards: turn whichever way stays inside
      for (int c = 1; c < 3 && choice < 0; ++c) {
        const int ni = i + options[c][0], nj = j + options[c][1];
        if (ni >= 0 && ni < n && nj >= 0 && nj < n) choice = c;
      }
    }
    di = options[choice][0];
    dj = options[choice][1];
    i += di;
    j += dj;
    w.route.emplace_back(i * pitch, j * pitch);
    length += pitch;
  }
  w.route_closed = false;
}

}  // namespace

WorldConfig worldConfigFor(const std::string& name, std::uint64_t seed) {
  WorldConfig c;
  c.name = name;
  c.seed = seed;
  if (name == "roadway-straight" || name == "roadway-loop") return c;
  if (name == "room-and-pillar") {
    c.width = 5.0;
    c.wall_height = 3.0;
    c.roof_rise = 0.0;  // flat roof in a coal seam
    c.support_arches = false;
    c.services = false;
    c.equipment = false;
    c.side_cuts = false;
    c.grade_amplitude = 0.3;
    return c;
  }
  if (name == "featureless") {
    c.roof_rise = 1.0;  // smooth shotcreted arch
    c.floor_roughness = 0.005;
    c.wall_roughness = 0.0;
    c.grade_amplitude = 0.0;
    c.support_arches = c.roof_bolts = c.services = c.equipment = c.side_cuts = false;
    return c;
  }
  throw std::invalid_argument("sim: unknown world '" + name +
                              "' (roadway-straight, roadway-loop, room-and-pillar, featureless)");
}

WorldConfig worldConfigFrom(const adit::Config& cfg, const std::string& name, std::uint64_t seed) {
  WorldConfig c = worldConfigFor(name, seed);
  const std::string p = "sim.roadway.";
  c.width = cfg.get(p + "width", c.width);
  c.wall_height = cfg.get(p + "wall_height", c.wall_height);
  c.roof_rise = cfg.get(p + "roof_rise", c.roof_rise);
  c.floor_roughness = cfg.get(p + "floor_roughness", c.floor_roughness);
  c.wall_roughness = cfg.get(p + "wall_roughness", c.wall_roughness);
  c.grade_amplitude = cfg.get(p + "grade_amplitude", c.grade_amplitude);
  c.support_arches = cfg.get(p + "support_arches", c.support_arches);
  c.arch_spacing = cfg.get(p + "arch_spacing", c.arch_spacing);
  c.roof_bolts = cfg.get(p + "roof_bolts", c.roof_bolts);
  c.bolt_spacing = cfg.get(p + "bolt_spacing", c.bolt_spacing);
  c.services = cfg.get(p + "services", c.services);
  c.equipment = cfg.get(p + "equipment", c.equipment);
  c.side_cuts = cfg.get(p + "side_cuts", c.side_cuts);
  c.straight_length = cfg.get(p + "straight_length", c.straight_length);
  c.loop_size_x = cfg.get(p + "loop_size_x", c.loop_size_x);
  c.loop_size_y = cfg.get(p + "loop_size_y", c.loop_size_y);
  c.loop_crosscuts = cfg.get(p + "loop_crosscuts", c.loop_crosscuts);
  c.pillar_grid = cfg.get(p + "pillar_grid", c.pillar_grid);
  c.pillar_size = cfg.get(p + "pillar_size", c.pillar_size);
  c.route_length = cfg.get(p + "route_length", c.route_length);
  return c;
}

double World::routeLength() const {
  double length = 0.0;
  for (std::size_t i = 1; i < route.size(); ++i) length += (route[i] - route[i - 1]).norm();
  return length;
}

World buildWorld(const WorldConfig& config) {
  (void)worldConfigFor(config.name);  // validates the name
  if (!(config.width > 1.0 && config.wall_height > 0.5 && config.roof_rise >= 0.0 && config.arch_spacing > 0.2 &&
        config.bolt_spacing > 0.2 && config.straight_length > 3 * config.width && config.loop_size_x > 3 * config.width &&
        config.loop_size_y > 3 * config.width && config.pillar_size > 1.0))
    throw std::invalid_argument("sim: invalid world sizes for '" + config.name + "'");
  World w;
  w.config = config;
  Rng rng = Rng::forStream(config.seed, Stream::World);
  w.floor_relief = WaveField(rng, 24, 1.5, 12.0, config.floor_roughness, true);
  w.grade = WaveField(rng, 3, 150.0, 400.0, config.grade_amplitude / std::sqrt(2.0), true);
  w.wall_relief = WaveField(rng, 24, 1.5, 6.0, config.wall_roughness, false);
  if (config.name == "roadway-loop") {
    layoutLoop(w, rng);
  } else if (config.name == "room-and-pillar") {
    layoutRoomAndPillar(w, rng);
  } else {
    layoutStraight(w);
  }
  addRoadwayGeometry(w, rng);
  w.scene.build();
  return w;
}

}  // namespace adit::sim
