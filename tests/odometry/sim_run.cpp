#include "sim_run.hpp"

#include "features/feature_extractor.hpp"
#include "sim/simulator.hpp"

#include <deque>

namespace adit::test {

FeatureConfig featureConfigForSensor(const std::string& sensor) {
  FeatureConfig fc;
  if (sensor == "hdl64") {
    fc.preprocess.num_rings = 64;
    fc.preprocess.min_elevation_deg = -24.9f;
    fc.preprocess.max_elevation_deg = 2.0f;
  }
  return fc;
}

SimRun simulateRun(const std::string& world, const std::string& sensor, double seconds, std::uint64_t seed) {
  return simulateRun(world, sensor, seconds, seed, featureConfigForSensor(sensor));
}

SimRun simulateRun(const std::string& world, const std::string& sensor, double seconds, std::uint64_t seed,
                   const FeatureConfig& features) {
  sim::SimConfig config;
  config.world = world;
  config.sensor = sensor;
  config.duration_s = seconds;
  config.seed = seed;
  sim::Simulator simulator(config);
  const FeatureExtractor extractor(features);
  SimRun run;
  std::deque<ImuSample> imu;
  sim::SimEvent event;
  while (simulator.next(event)) {
    if (event.kind == sim::SimEvent::Kind::Imu) {
      imu.push_back(event.imu);
      continue;
    }
    // IMU samples covering this sweep (plus one either side for interpolation).
    const std::int64_t start = event.scan.utime - toUtime(event.scan.sweep_duration) - 20000;
    while (!imu.empty() && imu.front().utime < start) imu.pop_front();
    run.features.push_back(extractor.process(event.scan, {imu.begin(), imu.end()}, MotionPrior{}));
    run.truth.push_back(event.truth);
  }
  return run;
}

}  // namespace adit::test
