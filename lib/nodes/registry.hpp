// The pipeline's nodes by name: the one place processes and `adit replay` get them from.
#pragma once

#include "core/config.hpp"
#include "runtime/node.hpp"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace adit::nodes {

// Pipeline order: feature -> odometry -> mapper -> loop_closer. makeNode also builds "relocaliser" (after
// the mapper; only for a run given a map bundle, reloc.prior_map).
const std::vector<std::string>& pipelineNodeNames();

// Builds a node from the whole configuration (it reads its own section) after validating all of it
// (validatePipelineConfig). Throws ConfigError on a bad config, std::runtime_error on an unknown name.
std::unique_ptr<runtime::Node> makeNode(const std::string& name, const Config& config);

// Every configuration key the pipeline's nodes read, with the value they resolve to under `config`
// (the built-in default where config does not set it).
std::map<std::string, std::string> pipelineConfigKeys(const Config& config);

}  // namespace adit::nodes
