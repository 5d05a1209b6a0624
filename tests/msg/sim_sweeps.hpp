// A few simulated sweeps of a sensor, with its firing table: what the compact codec tests encode.
#pragma once

#include "sim/simulator.hpp"
#include "sources/sim_source.hpp"

#include <string>
#include <vector>

namespace adit::test {

struct SimSweeps {
  msg::FiringTable table;
  std::vector<LidarScan> sweeps;
};

inline SimSweeps simulateSweeps(const std::string& sensor, int count, const std::string& world = "roadway-loop") {
  sim::SimConfig c;
  c.world = world;
  c.sensor = sensor;
  c.duration_s = 0.1 * count + 0.05;
  c.seed = 4;
  sim::Simulator simulator(c);
  SimSweeps out;
  out.table = sources::firingTableOf(simulator.lidar().profile());
  sim::SimEvent e;
  while (static_cast<int>(out.sweeps.size()) < count && simulator.next(e))
    if (e.kind == sim::SimEvent::Kind::Scan) out.sweeps.push_back(e.scan);
  return out;
}

}  // namespace adit::test
