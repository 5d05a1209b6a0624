// adit-odometry as a node: FEATURES (+ IMU for the rotation prior) -> ODOM_SCAN.
#pragma once

#include "core/config.hpp"
#include "runtime/node.hpp"

#include <memory>

namespace adit::nodes {

std::unique_ptr<runtime::Node> makeOdometryNode(const Config& config);

}  // namespace adit::nodes
