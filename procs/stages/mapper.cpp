// adit-mapper: Scan-to-map mapping: ODOM_SCAN (+POSE_GRAPH) -> ODOM_MAPPED
#include "nodes/registry.hpp"
#include "runtime/process.hpp"

int main(int argc, char** argv) {
  return adit::runtime::runNodeProcess(argc, argv, "mapper", "Scan-to-map mapping: ODOM_SCAN (+POSE_GRAPH) -> ODOM_MAPPED",
                                       [](const adit::Config& c) { return adit::nodes::makeNode("mapper", c); });
}
