// Turns a World's road network into geometry: roadway shells (floor, walls, arched or flat roof), junction
// chambers, and the furniture of a coal-mine roadway. Internal to the simulator (used by buildWorld).
#pragma once

#include "sim/world.hpp"

namespace adit::sim {

// Adds the geometry of every node and edge of world.network to world.scene (does not build the BVH).
// Furniture placement draws from `rng` in a fixed order, so a seed gives the same world bit for bit.
void addRoadwayGeometry(World& world, Rng& rng);

}  // namespace adit::sim
