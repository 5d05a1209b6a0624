// adit-loop-closer: Scan Context loop closure and pose graph: ODOM_MAPPED -> LOOP_CLOSURE, POSE_GRAPH
#include "nodes/registry.hpp"
#include "runtime/process.hpp"

int main(int argc, char** argv) {
  return adit::runtime::runNodeProcess(argc, argv, "loop-closer", "Scan Context loop closure and pose graph: ODOM_MAPPED -> LOOP_CLOSURE, POSE_GRAPH",
                                       [](const adit::Config& c) { return adit::nodes::makeNode("loop_closer", c); });
}
