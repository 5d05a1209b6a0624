// adit-feature as a node: LIDAR_POINTS (+ IMU, + ODOM_SCAN for the constant-velocity prior) -> FEATURES.
#pragma once

#include "core/config.hpp"
#include "runtime/node.hpp"

#include <memory>

namespace adit::nodes {

std::unique_ptr<runtime::Node> makeFeatureNode(const Config& config);

}  // namespace adit::nodes
