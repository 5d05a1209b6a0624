#include "nodes/registry.hpp"

#include "nodes/feature_node.hpp"
#include "nodes/loop_closer_node.hpp"
#include "nodes/mapper_node.hpp"
#include "nodes/node_config.hpp"
#include "nodes/odometry_node.hpp"
#include "nodes/relocaliser_node.hpp"
#include "runtime/process.hpp"

namespace adit::nodes {

const std::vector<std::string>& pipelineNodeNames() {
  static const std::vector<std::string> names{"feature", "odometry", "mapper", "loop_closer"};
  return names;
}

std::unique_ptr<runtime::Node> makeNode(const std::string& name, const Config& config) {
  validatePipelineConfig(config);
  std::unique_ptr<runtime::Node> node;
  if (name == "feature") node = makeFeatureNode(config);
  else if (name == "odometry") node = makeOdometryNode(config);
  else if (name == "mapper") node = makeMapperNode(config);
  else if (name == "loop_closer") node = makeLoopCloserNode(config);
  else if (name == "relocaliser") node = makeRelocaliserNode(config);
  else throw std::runtime_error("no pipeline node named '" + name + "'");
  node->setInputChecks(inputChecksFrom(config));
  return node;
}

std::map<std::string, std::string> pipelineConfigKeys(const Config& config) {
  std::map<std::string, std::string> keys;
  for (const auto& info : pipelineConfigDescription(config)) keys[info.key] = info.value;
  return keys;
}

}  // namespace adit::nodes
