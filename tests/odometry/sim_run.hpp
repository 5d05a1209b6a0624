// Feature sets of a simulated drive (lib/sim + FeatureExtractor), prepared once for tests and benchmarks:
// the feature stage is run as the pipeline runs it, deskewing each sweep with the IMU samples that cover it.
#pragma once

#include "core/types.hpp"

#include <string>
#include <vector>

namespace adit::test {

struct SimRun {
  std::vector<FeatureSet> features;
  std::vector<StampedPose> truth;  // T_world_lidar at each sweep's utime
};

// Simulates `seconds` of `world` with `sensor` (see sim::SimConfig) and extracts features of every sweep.
SimRun simulateRun(const std::string& world, const std::string& sensor, double seconds, std::uint64_t seed = 1);

}  // namespace adit::test
