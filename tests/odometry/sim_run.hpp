// Feature sets of a simulated drive (lib/sim + FeatureExtractor), prepared once for tests and benchmarks:
// the feature stage is run as the pipeline runs it, deskewing each sweep with the IMU samples that cover it.
#pragma once

#include "core/types.hpp"
#include "features/feature_config.hpp"

#include <string>
#include <vector>

namespace adit::test {

struct SimRun {
  std::vector<FeatureSet> features;
  std::vector<StampedPose> truth;  // T_world_lidar at each sweep's utime
};

// Feature-stage defaults for a simulated sensor (ring elevations of the hdl64 profile).
FeatureConfig featureConfigForSensor(const std::string& sensor);

// Simulates `seconds` of `world` with `sensor` (see sim::SimConfig) and extracts features of every sweep.
SimRun simulateRun(const std::string& world, const std::string& sensor, double seconds, std::uint64_t seed = 1);
// Same with an explicit feature configuration.
SimRun simulateRun(const std::string& world, const std::string& sensor, double seconds, std::uint64_t seed,
                   const FeatureConfig& features);

}  // namespace adit::test
