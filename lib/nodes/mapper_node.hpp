// adit-mapper as a node: ODOM_SCAN (+ POSE_GRAPH corrections, + MAPPER_COMMAND "save_map") -> ODOM_MAPPED.
#pragma once

#include "core/config.hpp"
#include "runtime/node.hpp"

#include <memory>

namespace adit::nodes {

std::unique_ptr<runtime::Node> makeMapperNode(const Config& config);

}  // namespace adit::nodes
