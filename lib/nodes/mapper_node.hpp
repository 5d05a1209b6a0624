// adit-mapper as a node: ODOM_SCAN (+ POSE_GRAPH corrections) -> ODOM_MAPPED. Live, it checkpoints its local
// map into the run folder and resumes from it after a restart. The map a run saves is the loop closer's.
#pragma once

#include "core/config.hpp"
#include "runtime/node.hpp"

#include <memory>

namespace adit::nodes {

std::unique_ptr<runtime::Node> makeMapperNode(const Config& config);

}  // namespace adit::nodes
