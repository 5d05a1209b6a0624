// The pipeline's nodes by name: the one place processes and `adit replay` get them from.
#pragma once

#include "core/config.hpp"
#include "runtime/node.hpp"

#include <memory>
#include <string>
#include <vector>

namespace adit::nodes {

// Pipeline order: feature -> odometry -> mapper -> loop_closer.
const std::vector<std::string>& pipelineNodeNames();

// Builds a node from the whole configuration (it reads its own section). Throws
// runtime::StageNotImplemented if that stage is not written yet, std::runtime_error on bad config.
std::unique_ptr<runtime::Node> makeNode(const std::string& name, const Config& config);

}  // namespace adit::nodes
