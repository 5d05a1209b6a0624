// adit-loop-closer as a node: ODOM_MAPPED -> LOOP_CLOSURE (each accepted loop) and POSE_GRAPH (after each
// re-optimisation; the mapper applies its correction).
#pragma once

#include "core/config.hpp"
#include "runtime/node.hpp"

#include <memory>

namespace adit::nodes {

std::unique_ptr<runtime::Node> makeLoopCloserNode(const Config& config);

}  // namespace adit::nodes
