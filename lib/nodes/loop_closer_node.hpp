// adit-loop-closer as a node: ODOM_MAPPED -> LOOP_CLOSURE (each accepted loop) and POSE_GRAPH (after each
// re-optimisation; the mapper applies its correction). It owns the run's corrected map: MAPPER_COMMAND
// "save_map [NAME]" writes map, trajectory and pose graph into the run folder, MAP_UPDATE carries what
// changed for viewers, and its checkpoint (keyframes + graph) survives a restart.
#pragma once

#include "core/config.hpp"
#include "runtime/node.hpp"

#include <memory>

namespace adit::nodes {

std::unique_ptr<runtime::Node> makeLoopCloserNode(const Config& config);

}  // namespace adit::nodes
