#include "nodes/registry.hpp"

#include "nodes/feature_node.hpp"
#include "nodes/loop_closer_node.hpp"
#include "nodes/mapper_node.hpp"
#include "nodes/node_config.hpp"
#include "nodes/odometry_node.hpp"
#include "runtime/process.hpp"

namespace adit::nodes {

const std::vector<std::string>& pipelineNodeNames() {
  static const std::vector<std::string> names{"feature", "odometry", "mapper", "loop_closer"};
  return names;
}

std::unique_ptr<runtime::Node> makeNode(const std::string& name, const Config& config) {
  validatePipelineConfig(config);
  if (name == "feature") return makeFeatureNode(config);
  if (name == "odometry") return makeOdometryNode(config);
  if (name == "mapper") return makeMapperNode(config);
  if (name == "loop_closer") return makeLoopCloserNode(config);
  throw std::runtime_error("no pipeline node named '" + name + "'");
}

std::map<std::string, std::string> pipelineConfigKeys(const Config& config) {
  std::map<std::string, std::string> keys;
  for (const auto& info : pipelineConfigDescription(config)) keys[info.key] = info.value;
  return keys;
}

}  // namespace adit::nodes
