// adit-relocaliser: relocalisation on a saved map bundle (reloc.prior_map): ODOM_MAPPED -> POSE_IN_MAP
#include "nodes/registry.hpp"
#include "runtime/process.hpp"

int main(int argc, char** argv) {
  return adit::runtime::runNodeProcess(argc, argv, "relocaliser",
                                       "Relocalisation on a saved map bundle (reloc.prior_map): ODOM_MAPPED -> POSE_IN_MAP",
                                       [](const adit::Config& c) { return adit::nodes::makeNode("relocaliser", c); });
}
