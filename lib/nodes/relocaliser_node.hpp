// adit-relocaliser as a node (issue 18): ODOM_MAPPED -> POSE_IN_MAP, the run's pose in a saved map bundle's
// frame (reloc.prior_map), published only once relocalised. STATUS state: relocalising / localised, or
// mapping_from_scratch when the bundle cannot be used (the error says why).
#pragma once

#include "core/config.hpp"
#include "runtime/node.hpp"

#include <memory>

namespace adit::nodes {

std::unique_ptr<runtime::Node> makeRelocaliserNode(const Config& config);

}  // namespace adit::nodes
