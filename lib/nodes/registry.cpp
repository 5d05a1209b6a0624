#include "nodes/registry.hpp"

#include "runtime/process.hpp"

namespace adit::nodes {

const std::vector<std::string>& pipelineNodeNames() {
  static const std::vector<std::string> names{"feature", "odometry", "mapper", "loop_closer"};
  return names;
}

std::unique_ptr<runtime::Node> makeNode(const std::string& name, const Config& /*config*/) {
  if (name == "feature")
    throw runtime::StageNotImplemented("the feature stage (preprocessing, deskew, LOAM, LinK3D) is not written yet: issue 4");
  if (name == "odometry")
    throw runtime::StageNotImplemented("the scan-to-scan odometry stage is not written yet: issue 5");
  if (name == "mapper")
    throw runtime::StageNotImplemented("the scan-to-map mapping stage is not written yet: issue 5");
  if (name == "loop_closer")
    throw runtime::StageNotImplemented("the loop-closure stage (Scan Context + pose graph) is not written yet: issue 6");
  throw std::runtime_error("no pipeline node named '" + name + "'");
}

}  // namespace adit::nodes
