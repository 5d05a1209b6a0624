// adit-feature: Preprocessing, deskew, LOAM features and LinK3D keypoints: LIDAR_POINTS (+IMU) -> FEATURES
#include "nodes/registry.hpp"
#include "runtime/process.hpp"

int main(int argc, char** argv) {
  return adit::runtime::runNodeProcess(argc, argv, "feature", "Preprocessing, deskew, LOAM features and LinK3D keypoints: LIDAR_POINTS (+IMU) -> FEATURES",
                                       [](const adit::Config& c) { return adit::nodes::makeNode("feature", c); });
}
