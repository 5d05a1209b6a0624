// adit-odometry: Scan-to-scan odometry: FEATURES -> ODOM_SCAN
#include "nodes/registry.hpp"
#include "runtime/process.hpp"

int main(int argc, char** argv) {
  return adit::runtime::runNodeProcess(argc, argv, "odometry", "Scan-to-scan odometry: FEATURES -> ODOM_SCAN",
                                       [](const adit::Config& c) { return adit::nodes::makeNode("odometry", c); });
}
